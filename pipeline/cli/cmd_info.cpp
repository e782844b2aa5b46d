// sylva info: what a scene, mesh, grid or cache file holds (pipeline/services/file_info describes it).
#include <cstdio>

#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/services/file_info.h"

namespace sylva::cli {
namespace {

int runInfo(const Args& args)
{
    std::fputs(describeFile(args.positional()[0]).c_str(), stdout);
    return kOk;
}

} // namespace

Command infoCommand()
{
    return {"info", "FILE", "print what a scene (.json), mesh, grid (.npy, .vdb) or cache file holds", {}, 1, 1, &runInfo};
}

} // namespace sylva::cli
