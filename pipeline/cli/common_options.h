// Options that several commands share (threads, output, cache, backend) and what they turn into.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "core/backend/backend.h"
#include "core/sky/sun_position.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/cli/args.h"
#include "pipeline/io/file_extension.h"

namespace sylva::cli {

inline const OptionSpec kQuiet{"--quiet", "", "no progress output"};
inline const OptionSpec kThreads{"--threads", "N", "worker threads (default: all cores)"};
inline const OptionSpec kOutput{"--output", "FILE", "output file (also -o)"};
inline const OptionSpec kCache{"--cache", "DIR", "grid cache folder (default $XDG_CACHE_HOME/sylva or ~/.cache/sylva)"};
inline const OptionSpec kNoCache{"--no-cache", "", "neither read nor write the grid cache"};
inline const OptionSpec kBackend{"--backend", "auto|cpu|cuda", "compute backend (default auto)"};
inline const OptionSpec kSunAt{"--sun-at", "DATE,TIME,ZONE,LAT,LON",
                               "the sun by date and place (NOAA's solar position, about 0.02 degrees): YYYY-MM-DD,HH:MM[:SS] "
                               "local time, hours ahead of UTC (east +), latitude (north +), longitude (east +)"};

// --threads N: the limit lives as long as the returned object (null without the option).
std::unique_ptr<tbb::global_control> threadLimit(const Args& args);
// The grid cache of --cache DIR (or the default folder); null with --no-cache.
std::unique_ptr<GridCache> openCache(const Args& args);
// Throws Error "PATH: no such WHAT" / "PATH: is a folder, not a WHAT".
void requireReadable(const std::string& path, const char* what);
// The value of --sun-at (kSunAt's form), its ranges checked (UsageError naming the option and the field).
sky::SunPlace parseSunAt(const std::string& text);
// --backend, checked (UsageError for another name); "auto" without the option.
std::string backendName(const Args& args);
// The backend of that name; notes (CUDA requested but absent, ...) go to stderr as "note: ...".
std::unique_ptr<Backend> openBackend(const std::string& name);
// lowerExtension(path): ".PNG" -> ".png" (the pipeline's one, here for the commands).
using sylva::lowerExtension;
// The file of --output (-o) of a command that writes the formats `extensions` (".npy", ...), checked
// before any work: `fallback` without the option (an empty fallback: the option is required,
// UsageError), UsageError "output PATH: cannot write .x files (use ...)" for another extension (today
// `-o x.vdb` would otherwise get NumPy bytes). Every command with -o takes its output through this; the
// command then checks the file itself (requireReplaceableFile) after its other usage checks.
std::string outputFile(const Args& args, const std::vector<std::string>& extensions, const std::string& fallback = {});

} // namespace sylva::cli
