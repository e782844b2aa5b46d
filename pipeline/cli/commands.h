// The `sylva` commands, one file each (cmd_NAME.cpp): each returns its description and function.
// main.cpp lists them in the order `sylva --help` shows.
#pragma once

#include "pipeline/cli/args.h"

namespace sylva::cli {

Command growCommand();        // cmd_grow.cpp
Command voxelizeCommand();    // cmd_voxelize.cpp
Command lightCommand();       // cmd_light.cpp
Command referenceCommand();   // cmd_reference.cpp
Command renderCommand();      // cmd_render.cpp
Command studyCommand();       // cmd_study.cpp
Command infoCommand();        // cmd_info.cpp
Command skyCommand();         // cmd_sky.cpp
Command cacheCommand();       // cmd_cache.cpp
Command exportCommand();      // cmd_export.cpp
Command volumeCommand();      // cmd_volume.cpp
Command simulateCommand();    // cmd_simulate.cpp

} // namespace sylva::cli
