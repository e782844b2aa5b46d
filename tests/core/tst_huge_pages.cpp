// The program's operator new (core/base/global_new.cpp) asks for transparent huge pages on large blocks:
// the kernel's record of the mapping (/proc/self/smaps VmFlags "hg") says whether it was asked, and
// AnonHugePages how much of it the kernel then backed with 2 MB pages.
#include <QTest>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/huge_pages.h"

using namespace sylva;

namespace {

struct Mapping {
    bool found = false;
    bool advised = false;   // VmFlags holds "hg" (madvise MADV_HUGEPAGE)
    long anonHugeKb = 0;
};

// The /proc/self/smaps entry of the mapping that holds address a.
Mapping mappingOf(const void* a)
{
    const auto addr = reinterpret_cast<uintptr_t>(a);
    std::ifstream in("/proc/self/smaps");
    std::string line;
    Mapping m;
    bool inside = false;
    while (std::getline(in, line)) {
        unsigned long lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
            if (inside) break;   // the next mapping
            inside = addr >= lo && addr < hi;
            m.found = inside;
            continue;
        }
        if (!inside) continue;
        if (line.rfind("AnonHugePages:", 0) == 0) m.anonHugeKb = std::stol(line.substr(14));
        if (line.rfind("VmFlags:", 0) == 0) m.advised = (line + " ").find(" hg ") != std::string::npos;
    }
    return m;
}

bool thpUsable()
{
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string mode;
    std::getline(in, mode);
    return !mode.empty() && mode.find("[never]") == std::string::npos;
}

} // namespace

class TstHugePages : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void largeBlocksAskForHugePages()
    {
        if (!thpUsable()) QSKIP("this kernel has transparent huge pages off (or none): nothing to ask for");
        QVERIFY2(hugePagesAdvised(), "SYLVA_HUGE_PAGES=0 is set: the test needs the default");
        // A vector's storage through operator new: the 2 MB pages inside the block are advised.
        const size_t n = size_t(64) << 20;
        std::vector<char> big(n);   // value-initialized: every page touched
        const uintptr_t mid = (reinterpret_cast<uintptr_t>(big.data()) + n / 2) & ~((uintptr_t(2) << 20) - 1);
        const Mapping m = mappingOf(reinterpret_cast<const void*>(mid));
        QVERIFY(m.found);
        QVERIFY2(m.advised, "a 64 MB block's middle is not advised for huge pages: operator new is not ours");
        qInfo("64 MB block: %ld kB of it in huge pages", m.anonHugeKb);
        // new[] and aligned new take the same path.
        std::unique_ptr<float[]> arr(new float[size_t(8) << 20]);
        QVERIFY(mappingOf(arr.get() + (size_t(4) << 20)).advised);
        struct alignas(64) Line { char b[64]; };
        std::unique_ptr<Line[]> lines(new Line[size_t(1) << 17]);
        QVERIFY(mappingOf(lines.get() + (size_t(1) << 16)).advised);
    }

    void smallBlocksAreLeftAlone()
    {
        if (!thpUsable()) QSKIP("this kernel has transparent huge pages off (or none)");
        // Under the threshold nothing is asked: a block of 1 MB stays in ordinary pages.
        std::vector<char> small(size_t(1) << 20, 1);
        const Mapping m = mappingOf(small.data() + small.size() / 2);
        QVERIFY(m.found);
        QVERIFY2(!m.advised, "a 1 MB block was advised");
        // adviseHugePages on a range with no whole 2 MB page inside does nothing (and does not fail).
        adviseHugePages(small.data(), small.size());
        QVERIFY(!mappingOf(small.data() + small.size() / 2).advised);
    }
};

QTEST_GUILESS_MAIN(TstHugePages)
#include "tst_huge_pages.moc"
