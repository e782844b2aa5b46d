// The table of `sylva`'s commands and the command line run over a table: `sylva --help` and `--version`,
// the hidden `--man` and `--completion`, a command's `--help`, and what a command throws mapped to the exit
// code: 0 ok, 1 bad input or failure, 2 bad usage, 128 + signal when SIGINT (130) or SIGTERM (143)
// cancelled the job. main.cpp runs the table; tests run it with commands of their own added.
#include <csignal>
#include <cstdio>
#include <new>

#include "core/base/error.h"
#include "core/base/version.h"
#include "pipeline/backend_info.h"
#include "pipeline/cli/cli_docs.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"

namespace sylva::cli {
namespace {

void printMainHelp(const std::vector<Command>& cmds)
{
    std::printf("sylva %s: forests with lattice-Boltzmann lighting\n\nusage: sylva COMMAND [options]\n\ncommands:\n",
                versionString());
    for (const auto& c : cmds) std::printf("  %-10s %s\n", c.name.c_str(), c.summary.c_str());
    std::printf("\n  sylva COMMAND --help   options of a command\n  sylva --version        version and compute backends\n");
}

} // namespace

std::vector<Command> commandTable()
{
    return {growCommand(), voxelizeCommand(), lightCommand(), referenceCommand(), renderCommand(), skyCommand(), volumeCommand(), simulateCommand(), exportCommand(), studyCommand(), infoCommand(), cacheCommand()};
}

int runCommandLine(const std::vector<Command>& cmds, const std::vector<std::string>& argsv)
{
    if (argsv.empty() || argsv[0] == "-h" || argsv[0] == "--help" || argsv[0] == "help") {
        printMainHelp(cmds);
        return argsv.empty() ? kUsage : kOk;
    }
    if (argsv[0] == "--version") {
        std::printf("sylva %s\nbackends: %s\n", versionString(), backendSummary().c_str());
        return kOk;
    }
    // Hidden: the man page and the bash completion from this table (the build installs their output).
    if (argsv[0] == "--man" || argsv[0] == "--completion") {
        std::fputs((argsv[0] == "--man" ? manPage(cmds) : bashCompletion(cmds)).c_str(), stdout);
        return kOk;
    }
    const Command* cmd = nullptr;
    for (const auto& c : cmds)
        if (c.name == argsv[0]) cmd = &c;
    if (!cmd) {
        std::fprintf(stderr, "sylva: unknown command '%s' (see sylva --help)\n", argsv[0].c_str());
        return kUsage;
    }
    cancelOnSignals();
    try {
        const Args args(*cmd, std::vector<std::string>(argsv.begin() + 1, argsv.end()));
        if (args.help()) {
            printHelp(*cmd);
            return kOk;
        }
        return cmd->run(args);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "sylva %s: %s\n", cmd->name.c_str(), e.what());
        return kUsage;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "sylva %s: error: out of memory (try a smaller --grid or --fp16)\n", cmd->name.c_str());
        return kFailure;
    } catch (const Cancelled&) {
        const int sig = cancelSignal();
        if (sig == 0) {
            std::fprintf(stderr, "sylva %s: cancelled\n", cmd->name.c_str());
            return kFailure;
        }
        std::fprintf(stderr, "sylva %s: cancelled by %s; no partial output was left\n", cmd->name.c_str(),
                     sig == SIGINT ? "SIGINT (Ctrl-C)" : "SIGTERM");
        return 128 + sig;   // 130 for Ctrl-C, as shells report an interrupted program
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sylva %s: error: %s\n", cmd->name.c_str(), e.what());
        return kFailure;
    }
}

} // namespace sylva::cli
