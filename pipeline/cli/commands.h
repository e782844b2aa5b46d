// The `sylva` commands, one file each (cmd_NAME.cpp): each returns its description and function.
// commandTable (command_line.cpp) lists them in the order `sylva --help` shows; main.cpp runs it.
#pragma once

#include <string>
#include <vector>

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

// The commands in the order `sylva --help` lists them.
std::vector<Command> commandTable();

// `sylva ARGS...` over a table of commands (args without the program's name): `--help`, `--version`,
// `--man`, `--completion`, `COMMAND --help`, or the command run; what it throws is printed on stderr and
// mapped to the exit code returned: UsageError 2, Cancelled 1 (or 128 + the signal that asked for it),
// any other exception 1. Installs the SIGINT / SIGTERM handlers (cancelOnSignals) before a command runs.
int runCommandLine(const std::vector<Command>& commands, const std::vector<std::string>& args);

} // namespace sylva::cli
