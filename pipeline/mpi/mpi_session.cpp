// The start and end of an MPI job (mpi_session.h, mpi_common.h): MPI_Init with the build check, the launcher's
// environment, the end of a failed job.
#include "pipeline/mpi/mpi_session.h"

#include <mpi.h>
#include <unistd.h>
#include <xxhash.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/render/render_cpu.h"
#include "pipeline/mpi/mpi_common.h"
#include "pipeline/mpi/mpi_render.h"

namespace sylva::mpi {
namespace {

// The command of this process's job ("render", "light") and what a failed job did not write.
const char* g_command = "render";
const char* g_notWritten = "no picture was written";

// XXH3-64 of this process's executable: ranks run the same build only when their files are equal
// (a -march=native build of another machine may round differently, and the picture must not).
uint64_t executableHash()
{
    std::ifstream in("/proc/self/exe", std::ios::binary);
    if (!in) return 0;
    XXH3_state_t* state = XXH3_createState();
    XXH3_64bits_reset(state);
    std::vector<char> buf(1 << 20);
    while (in) {
        in.read(buf.data(), std::streamsize(buf.size()));
        if (in.gcount() > 0) XXH3_64bits_update(state, buf.data(), size_t(in.gcount()));
    }
    const uint64_t h = XXH3_64bits_digest(state);
    XXH3_freeState(state);
    return h;
}

struct BuildId {
    char version[32];
    char host[64];
    uint64_t exeHash;
    uint32_t partsBytes;   // sizeof(SampleParts): the tiles' wire format
    uint32_t reserved;
};

// "" when every rank runs rank 0's build, else the ranks that do not (the same text on every rank).
std::string checkBuilds(int size, std::vector<std::string>* hosts)
{
    BuildId me{};
    std::snprintf(me.version, sizeof me.version, "%s", versionString());
    std::snprintf(me.host, sizeof me.host, "%s", hostName().c_str());
    me.exeHash = executableHash();
    me.partsBytes = uint32_t(sizeof(SampleParts));
    std::vector<BuildId> all(static_cast<size_t>(size));
    check(MPI_Allgather(&me, int(sizeof me), MPI_BYTE, all.data(), int(sizeof me), MPI_BYTE, MPI_COMM_WORLD), "Allgather");
    std::string msg;
    for (const BuildId& b : all) hosts->push_back(std::string(b.host, strnlen(b.host, sizeof b.host)));
    const BuildId& lead = all[0];
    for (int r = 1; r < size; ++r) {
        const BuildId& b = all[size_t(r)];
        if (std::strncmp(b.version, lead.version, sizeof b.version) == 0 && b.exeHash == lead.exeHash && b.partsBytes == lead.partsBytes)
            continue;
        char line[400];
        std::snprintf(line, sizeof line, "%srank %d on %.64s runs sylva %.32s (executable %016llx), rank 0 on %.64s runs sylva %.32s (executable %016llx)",
                      msg.empty() ? "" : "; ", r, b.host, b.version, static_cast<unsigned long long>(b.exeHash), lead.host, lead.version,
                      static_cast<unsigned long long>(lead.exeHash));
        msg += line;
    }
    return msg;
}

} // namespace

void check(int rc, const char* what)
{
    if (rc == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int n = 0;
    MPI_Error_string(rc, text, &n);
    throw Error(std::string("MPI ") + what + " failed: " + std::string(text, size_t(n)));
}

std::string rankName(int r)
{
    char t[32];
    std::snprintf(t, sizeof t, "rank %d", r);
    return t;
}

std::string hostName()
{
    char h[256] = {};
    if (gethostname(h, sizeof h - 1) != 0) return "?";
    return h;
}

[[noreturn]] void abortJob(const std::string& message)
{
    std::fprintf(stderr, "sylva %s: error: %s; %s\n", g_command, message.c_str(), g_notWritten);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
    std::_Exit(1);
}

std::string jobError(const std::string& what) { return std::string("sylva ") + g_command + ": error: " + what + "; " + g_notWritten; }

int envInt(const char* name, int fallback)
{
    const char* v = std::getenv(name);
    return v && *v ? std::atoi(v) : fallback;
}

bool launchedByMpi()
{
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(name)) return true;
    return false;
}

int launchRank()
{
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"}) {
        const int r = envInt(name, -1);
        if (r >= 0) return r;
    }
    return 0;
}

int runSession(const char* command, const char* notWritten,
               const std::function<int(int rank, int size, const std::vector<std::string>& hosts)>& body, double timeoutSeconds)
{
    g_command = command;
    g_notWritten = notWritten;
    if (!launchedByMpi())
        throw Error(std::string("--mpi: this process was not started by mpirun; run it as: mpirun -np N sylva ") + command +
                    " --mpi ... (docs/DISTRIBUTED.md), or drop --mpi");
    // The start (MPI_Init and the build check) waits for every rank: one that hangs there, or never
    // starts, ends the job after the start bound (this process exits; mpirun then stops the others).
    const double startBound = 2.0 * timeoutSeconds + 5.0;
    char startMessage[160];
    std::snprintf(startMessage, sizeof startMessage, "--mpi: the ranks did not all start within %.0f s (a rank hung or could not start)", startBound);
    Deadline start(startBound, jobError(startMessage));
    int provided = 0;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) throw Error("--mpi: MPI_Init failed");
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (provided < MPI_THREAD_FUNNELED) {
        if (rank == 0) std::fprintf(stderr, "sylva %s: error: --mpi: this MPI library does not allow threads (MPI_THREAD_FUNNELED)\n", command);
        MPI_Finalize();
        return 1;
    }
    std::string mismatch;
    std::vector<std::string> hosts;
    try {
        mismatch = checkBuilds(size, &hosts);
    } catch (const Error& e) {
        abortJob(e.what());
    }
    if (!mismatch.empty()) {
        if (rank == 0)
            std::fprintf(stderr, "sylva %s: error: --mpi: the ranks run different builds of sylva (%s); install one build on every node\n",
                         command, mismatch.c_str());
        MPI_Finalize();
        return 1;
    }
    start.disarm();
    const int code = body(rank, size, hosts);
    MPI_Finalize();
    return code;
}

[[noreturn]] void endJob(const std::string& message) { abortJob(message); }

void checkMpi(int rc, const char* what) { check(rc, what); }

std::string thisHost() { return hostName(); }

} // namespace sylva::mpi
