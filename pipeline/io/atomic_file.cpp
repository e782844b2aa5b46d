// Atomic file writing for every writer (scene files, npy grids, cache entries, OBJ/MTL, images).
#include "pipeline/io/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/base/error.h"
#include "pipeline/io/output_path.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

// The file a path finally names: symbolic links followed (relative ones from their folder), so the
// link stays and its target is replaced. The path itself when it is no link or the chain is too long.
std::string resolveLinks(const std::string& path)
{
    fs::path p(path);
    std::error_code ec;
    for (int depth = 0; depth < 128; ++depth) {
        if (!fs::is_symlink(fs::symlink_status(p, ec))) return p.string();
        const fs::path next = fs::read_symlink(p, ec);
        if (ec) return path;
        p = next.is_absolute() ? next : p.parent_path() / next;
    }
    return path;
}

// The temporary files a signal handler may have to remove: fixed slots, claimed with a compare and
// swap, filled, then published (state 2); cleared before the path changes or the object goes.
constexpr int kPendingSlots = 64;
struct PendingSlot {
    std::atomic<int> state{0};   // 0 free, 1 being filled, 2 published
    char path[4096] = {};
};
PendingSlot g_pending[kPendingSlots];
static_assert(std::atomic<int>::is_always_lock_free);

int publishPending(const std::string& path)
{
    if (path.size() >= sizeof(PendingSlot::path)) return -1;
    for (int i = 0; i < kPendingSlots; ++i) {
        int expected = 0;
        if (!g_pending[i].state.compare_exchange_strong(expected, 1, std::memory_order_acquire)) continue;
        std::memcpy(g_pending[i].path, path.c_str(), path.size() + 1);
        g_pending[i].state.store(2, std::memory_order_release);
        return i;
    }
    return -1;
}

void retractPending(int& slot)
{
    if (slot >= 0) g_pending[slot].state.store(0, std::memory_order_release);
    slot = -1;
}

} // namespace

void removePendingAtomicFiles() noexcept
{
    for (PendingSlot& slot : g_pending)
        if (slot.state.load(std::memory_order_acquire) == 2) ::unlink(slot.path);
}

AtomicFile::AtomicFile(std::string target, Sync sync, std::string what)
    : m_target(std::move(target)), m_what(std::move(what)), m_sync(sync)
{
    requireReplaceableFile(m_target);
    m_final = resolveLinks(m_target);
    const fs::path path(m_final);
    const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir))
        throw Error(m_target + ": cannot create the folder " + dir.string() + (ec ? " (" + ec.message() + ")" : ""));
    // An existing file keeps its permissions; a read-only one is not replaced.
    struct stat existing {};
    const bool exists = ::stat(m_final.c_str(), &existing) == 0;
    if (exists && ::access(m_final.c_str(), W_OK) != 0)
        throw Error(m_target + ": cannot replace the " + m_what + " (" + std::strerror(errno) + ")");

    // pid + a process-wide counter make the name unique between processes and threads; O_EXCL makes
    // sure of it (a leftover of a crashed process with a reused pid is skipped, not overwritten).
    static std::atomic<unsigned> counter{0};
    const std::string prefix = ".tmp." + std::to_string(::getpid()) + ".";
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        m_temp = (dir / (prefix + std::to_string(counter.fetch_add(1)) + "." + path.filename().string())).string();
        fd = ::open(m_temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) {
        const int err = errno;
        m_temp.clear();
        throw Error(m_target + ": cannot create the " + m_what + " (" + std::strerror(err) + ")");
    }
    m_slot = publishPending(m_temp);
    if (exists) (void)::fchmod(fd, existing.st_mode & 07777);
    m_file = ::fdopen(fd, "wb");
    if (!m_file) {
        const int err = errno;
        ::close(fd);
        fail("create", err);
    }
}

AtomicFile::~AtomicFile()
{
    if (m_file) std::fclose(m_file);
    if (!m_committed && !m_temp.empty()) {
        std::error_code ec;
        fs::remove(m_temp, ec);
    }
    retractPending(m_slot);   // after the removal: a signal between the two finds the file gone
}

void AtomicFile::fail(const std::string& doing, int err)
{
    if (m_file) std::fclose(m_file);
    m_file = nullptr;
    std::error_code ec;
    if (!m_temp.empty()) fs::remove(m_temp, ec);
    retractPending(m_slot);
    m_temp.clear();
    const std::string what = doing == "move" ? "move the written " + m_what + " into place" : doing + " the " + m_what;
    throw Error(m_target + ": cannot " + what + " (" + std::strerror(err) + ")");
}

void AtomicFile::write(const void* data, size_t size)
{
    if (!m_file) throw Error(m_target + ": cannot write the " + m_what + " (it is closed)");
    if (size && std::fwrite(data, 1, size, m_file) != size) fail("write", errno);
}

const std::string& AtomicFile::pathForWriter()
{
    if (m_file) {
        const int closed = std::fclose(m_file);
        m_file = nullptr;
        if (closed != 0) fail("write", errno);
    }
    return m_temp;
}

void AtomicFile::commit()
{
    if (m_committed) return;
    if (m_temp.empty()) throw Error(m_target + ": cannot write the " + m_what + " (an earlier error removed it)");
    if (m_file) {
        if (std::fflush(m_file) != 0) fail("write", errno);
        if (m_sync == Sync::Yes && ::fsync(::fileno(m_file)) != 0) fail("write", errno);
        const int closed = std::fclose(m_file);
        m_file = nullptr;
        if (closed != 0) fail("write", errno);
    } else if (m_sync == Sync::Yes) {
        // Written by name by another library: sync through a fresh descriptor.
        const int fd = ::open(m_temp.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0 || ::fsync(fd) != 0) {
            const int err = errno;
            if (fd >= 0) ::close(fd);
            fail("write", err);
        }
        ::close(fd);
    }
    if (::rename(m_temp.c_str(), m_final.c_str()) != 0) fail("move", errno);
    m_committed = true;
    retractPending(m_slot);
}

} // namespace sylva
