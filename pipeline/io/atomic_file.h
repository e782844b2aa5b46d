// The one way Sylva writes a file atomically: a uniquely named temporary file in the target's folder,
// renamed over the target on commit, removed otherwise. Readers see the old file or the new one; of
// several concurrent writers of one path, one whole file is left. A target that is a symbolic link
// stays a link (the file it names is replaced); an existing file keeps its permissions, and a
// read-only one is refused.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace sylva {

class AtomicFile {
public:
    // Whether commit() flushes the data to the disk (fsync) before the rename, so a crash cannot
    // leave a renamed but empty file.
    enum class Sync { No, Yes };

    // Checks the target with requireReplaceableFile, creates its folder, and creates the temporary
    // file ".tmp.PID.N.NAME" beside the file it names (exclusively; the extension is kept, so writers
    // that pick a format by extension still work). `what` names the file in messages ("scene file",
    // "cache entry"). Throws Error "TARGET: ..." naming the target.
    explicit AtomicFile(std::string target, Sync sync = Sync::Yes, std::string what = "file");
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();   // removes the temporary file unless committed

    const std::string& target() const { return m_target; }
    const std::string& tempPath() const { return m_temp; }

    // Appends bytes (buffered). Throws Error naming the target.
    void write(const void* data, size_t size);
    void write(std::string_view text) { write(text.data(), text.size()); }

    // For writers that open the file by name themselves (image libraries): closes this object's
    // stream and returns the temporary path to write to; write() may not be called afterwards.
    const std::string& pathForWriter();

    // Flushes (and with Sync::Yes syncs) the data, closes the file and renames it over the target.
    // Throws Error naming the target; the temporary file is then removed.
    void commit();

private:
    [[noreturn]] void fail(const std::string& doing, int err);

    std::string m_target;   // as given (messages)
    std::string m_final;    // the file replaced: m_target with symbolic links followed
    std::string m_temp, m_what;
    Sync m_sync;
    std::FILE* m_file = nullptr;
    bool m_committed = false;
    int m_slot = -1;   // in the table removePendingAtomicFiles() reads
};

// Removes the temporary file of every AtomicFile neither committed nor destroyed, without locks or
// allocation: async-signal-safe, for a handler that ends the process at once (the CLI's second Ctrl-C;
// the first cancels the job, and unwinding removes the files). Files past the table's 64 slots are
// left (a crash leaves them too; `sylva cache clean` removes those of the cache).
void removePendingAtomicFiles() noexcept;

} // namespace sylva
