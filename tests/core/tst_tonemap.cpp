// Tone mapping: luminance, the sRGB transfer function, global Reinhard and the log-average exposure.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/base/error.h"
#include "core/base/parallel.h"
#include "core/render/render_cpu.h"
#include "core/render/tonemap.h"
#include "core/render/tonemap_film.h"

using namespace sylva;

namespace {

// The sRGB OETF written out in double from IEC 61966-2-1.
double srgbReference(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

// HDR-like RGB image: luminances log-normally spread over several decades (clipped to [0.05, 100]),
// with every 97th pixel black when withBlack is set.
std::vector<float> randomImage(size_t pixels, unsigned seed, bool withBlack)
{
    std::mt19937 rng(seed);
    std::lognormal_distribution<float> radiance(0.0f, 1.5f);
    std::uniform_real_distribution<float> tint(0.5f, 1.0f);
    std::vector<float> img(pixels * 3);
    for (size_t p = 0; p < pixels; ++p) {
        const float l = std::clamp(radiance(rng), 0.05f, 100.0f);
        for (int c = 0; c < 3; ++c) img[p * 3 + size_t(c)] = withBlack && p % 97 == 0 ? 0.0f : l * tint(rng);
    }
    return img;
}

} // namespace

class TestToneMap : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void luminanceWeights()
    {
        QCOMPARE(luminance(glm::vec3(1.0f)), 1.0f);
        QCOMPARE(luminance(glm::vec3(1.0f, 0.0f, 0.0f)), 0.2126f);
        QCOMPARE(luminance(glm::vec3(0.0f, 1.0f, 0.0f)), 0.7152f);
        QCOMPARE(luminance(glm::vec3(0.0f, 0.0f, 1.0f)), 0.0722f);
    }

    void srgbBreakpointsAndReference()
    {
        // The linear segment meets the power segment at linear 0.0031308 = encoded 0.04045.
        QVERIFY(std::fabs(srgbEncode(0.0031308f) - 0.04045f) < 1e-5f);
        QVERIFY(std::fabs(srgbDecode(0.04045f) - 0.0031308f) < 1e-6f);
        QCOMPARE(srgbEncode(0.0f), 0.0f);
        QCOMPARE(srgbEncode(1.0f), 1.0f);
        QCOMPARE(srgbDecode(0.0f), 0.0f);
        QCOMPARE(srgbDecode(1.0f), 1.0f);
        QVERIFY(std::fabs(srgbEncode(0.18f) - 0.46135f) < 1e-4f);   // middle grey encodes to ~118/255
        for (int i = 0; i <= 1000; ++i) {
            const double v = i / 1000.0;
            QVERIFY2(std::fabs(srgbEncode(float(v)) - srgbReference(v)) < 2e-6, qPrintable(QString::number(v)));
        }
    }

    void srgbClamps()
    {
        QCOMPARE(srgbEncode(-1.0f), 0.0f);
        QCOMPARE(srgbEncode(7.0f), 1.0f);
        QCOMPARE(srgbEncode(std::numeric_limits<float>::infinity()), 1.0f);
        QCOMPARE(srgbEncode(std::numeric_limits<float>::quiet_NaN()), 0.0f);
        QCOMPARE(srgbDecode(-0.5f), 0.0f);
        QCOMPARE(srgbDecode(2.0f), 1.0f);
    }

    void srgbRoundTrip()
    {
        for (int i = 0; i <= 4096; ++i) {
            const float v = float(i) / 4096.0f;
            QVERIFY2(std::fabs(srgbDecode(srgbEncode(v)) - v) < 2e-6f, qPrintable(QString::number(v)));
            QVERIFY2(std::fabs(srgbEncode(srgbDecode(v)) - v) < 2e-6f, qPrintable(QString::number(v)));
        }
        // All 256 8-bit codes survive decode -> encode -> quantize.
        for (int code = 0; code < 256; ++code)
            QCOMPARE(int(std::lround(srgbEncode(srgbDecode(code / 255.0f)) * 255.0f)), code);
    }

    void reinhardBlackIsZero()
    {
        QCOMPARE(reinhard(glm::vec3(0.0f), 1.0f), glm::vec3(0.0f));
        QCOMPARE(reinhard(glm::vec3(0.0f), 1e6f), glm::vec3(0.0f));
        QCOMPARE(reinhard(glm::vec3(-1.0f, 0.0f, 0.0f), 1.0f), glm::vec3(0.0f));   // negative luminance
        QCOMPARE(reinhard(glm::vec3(1.0f), 0.0f), glm::vec3(0.0f));
    }

    void reinhardMonotonicAndBelowOne()
    {
        const glm::vec3 tint(0.9f, 0.6f, 0.3f);
        float previous = -1.0f;
        for (double l = 1e-6; l < 1e5; l *= 1.1) {
            const glm::vec3 out = reinhard(tint * float(l), 0.5f);
            const float y = luminance(out);
            QVERIFY2(y > previous, qPrintable(QString::number(l)));
            QVERIFY2(y < 1.0f, qPrintable(QString("L = %1 -> %2").arg(l).arg(y)));
            previous = y;
        }
        // Far beyond float resolution of 1 - Ld the curve saturates at 1 without overshoot or NaN.
        for (float l : {1e8f, 1e20f, 1e37f}) {
            const float y = luminance(reinhard(tint * l, 0.5f));
            QVERIFY(std::isfinite(y) && y > 0.999f && y <= 1.0f + 1e-6f);
        }
        // Grey input: every channel follows L / (1 + L).
        for (float g : {0.01f, 0.18f, 1.0f, 5.0f, 100.0f}) {
            const glm::vec3 out = reinhard(glm::vec3(g), 1.0f);
            for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(out[c] - g / (1.0f + g)) < 1e-6f);
        }
    }

    void reinhardKeepsChromaticity()
    {
        const glm::vec3 in(2.0f, 1.0f, 0.5f);
        const glm::vec3 out = reinhard(in, 3.0f);
        QVERIFY(std::fabs(out.x / out.y - 2.0f) < 1e-5f && std::fabs(out.z / out.y - 0.5f) < 1e-5f);
        const float l = luminance(in) * 3.0f;
        QVERIFY(std::fabs(luminance(out) - l / (1.0f + l)) < 1e-6f);
    }

    void logAverageOfConstantImage()
    {
        for (float c : {0.0f, 0.01f, 0.18f, 1.0f, 250.0f}) {
            const std::vector<float> img(100000 * 3, c);
            const float avg = logAverageLuminance(img.data(), 100000, 3);
            // exp(log(delta + c)) = c + delta.
            QVERIFY2(std::fabs(avg - (c + 1e-4f)) <= 1e-5f * (c + 1e-4f) + 1e-7f, qPrintable(QString("%1 -> %2").arg(c).arg(avg)));
        }
    }

    void logAverageIsGeometricMeanAndHonoursStride()
    {
        // Half the pixels at 0.01, half at 1 (RGBA, stride 4, alpha ignored): exp of the mean log.
        std::vector<float> img;
        for (int i = 0; i < 1000; ++i) {
            const float v = i % 2 ? 1.0f : 0.01f;
            img.insert(img.end(), {v, v, v, 123.0f});
        }
        const double expected = std::sqrt((0.01 + 1e-4) * (1.0 + 1e-4));
        QVERIFY(std::fabs(logAverageLuminance(img.data(), 1000, 4) - expected) < 1e-5 * expected);
        // Non-finite pixels are left out; nothing left -> 0; an empty image -> 0.
        img[0] = std::numeric_limits<float>::infinity();
        img[4] = std::numeric_limits<float>::quiet_NaN();
        QVERIFY(std::fabs(logAverageLuminance(img.data(), 2, 4)) == 0.0f);
        QCOMPARE(logAverageLuminance(nullptr, 0, 3), 0.0f);
        QVERIFY_THROWS_EXCEPTION(Error, logAverageLuminance(img.data(), 10, 2));
    }

    void logAverageIsDeterministic()
    {
        const std::vector<float> img = randomImage(300000, 3, true);
        const float a = logAverageLuminance(img.data(), 300000, 3);
        for (int i = 0; i < 5; ++i) QCOMPARE(logAverageLuminance(img.data(), 300000, 3), a);
    }

    // A frame rendered in bands feeds the accumulator piece by piece: any split, chunk-aligned or not
    // (pieces of 1 pixel, within a chunk, across several chunks), gives the whole image's bits; and the
    // value is the geometric mean computed independently in long double.
    void logAverageInPiecesEqualsWhole()
    {
        const size_t n = 100003;
        const std::vector<float> img = randomImage(n, 3, true);
        const float whole = logAverageLuminance(img.data(), n, 3);
        long double sum = 0.0L;
        size_t count = 0;
        for (size_t i = 0; i < n; ++i) {
            const float l = luminance(glm::vec3(img[i * 3], img[i * 3 + 1], img[i * 3 + 2]));
            if (!std::isfinite(l)) continue;
            sum += std::log(1e-4L + (l > 0.0f ? l : 0.0f));
            ++count;
        }
        QVERIFY(std::fabs(double(whole) - double(std::exp(sum / count))) <= 1e-6 * double(whole));
        std::mt19937 rng(7);
        for (size_t piece : {size_t(1), size_t(7), size_t(16384), size_t(20000), size_t(50001), size_t(0)}) {
            LogAverageAccumulator acc;
            size_t at = 0;
            while (at < n) {
                const size_t len = std::min(n - at, piece ? piece : size_t(1 + rng() % 40000));
                acc.add(img.data() + at * 3, len, 3);
                at += len;
            }
            QCOMPARE(acc.value(), whole);
        }
    }

    void constantGreyMapsToReinhardOfKey()
    {
        // logAverage = L + delta, so scale * L = key * L / (L + delta) and the output is its Reinhard value.
        for (float grey : {0.05f, 1.0f, 40.0f}) {
            for (float key : {0.18f, 0.5f}) {
                const size_t n = 4096;
                const std::vector<float> img(n * 3, grey);
                std::vector<float> out(n * 3, -1.0f);
                toneMapToSrgb(img.data(), n, out.data(), ToneMapParams{key});
                const double l = double(key) * grey / (grey + 1e-4);
                const double expected = srgbReference(l / (1.0 + l));
                for (size_t i = 0; i < n * 3; ++i)
                    QVERIFY2(std::fabs(out[i] - expected) < 1e-5, qPrintable(QString("grey %1 key %2: %3 vs %4").arg(grey).arg(key).arg(out[i]).arg(expected)));
            }
        }
    }

    void exposureInvariance()
    {
        // Scaling the radiance by k scales the log-average by k too, so the result barely moves. This holds
        // while the pixels stay well above delta = 1e-4 (here kL >= 2.5e-3); black pixels would break it,
        // since log(delta + 0) does not shift with k (1% black pixels move the exposure by k^0.01).
        const size_t n = 50000;
        const std::vector<float> img = randomImage(n, 11, false);
        std::vector<float> ref(n * 3);
        toneMapToSrgb(img.data(), n, ref.data(), {});
        for (float k : {0.1f, 3.0f, 1000.0f}) {
            std::vector<float> scaled(img);
            for (float& v : scaled) v *= k;
            std::vector<float> out(n * 3);
            toneMapToSrgb(scaled.data(), n, out.data(), {});
            float worst = 0.0f;
            for (size_t i = 0; i < n * 3; ++i) worst = std::max(worst, std::fabs(out[i] - ref[i]));
            QVERIFY2(worst < 2e-3f, qPrintable(QString("k = %1: max difference %2").arg(k).arg(worst)));
        }
    }

    void outputInUnitRangeAndInPlace()
    {
        const size_t n = 70000;
        std::vector<float> img = randomImage(n, 5, true);
        img[3] = 1e30f;   // a very bright (firefly) pixel
        img[4] = std::numeric_limits<float>::quiet_NaN();
        std::vector<float> out(n * 3);
        toneMapToSrgb(img.data(), n, out.data(), {});
        for (float v : out) QVERIFY(v >= 0.0f && v <= 1.0f);
        toneMapToSrgb(img.data(), n, img.data(), {});   // in place gives the same result
        QVERIFY(img == out);
    }

    void badParamsThrow()
    {
        std::vector<float> img(30, 0.5f), out(30);
        QVERIFY_THROWS_EXCEPTION(Error, toneMapToSrgb(img.data(), 10, out.data(), ToneMapParams{0.0f}));
        QVERIFY_THROWS_EXCEPTION(Error, toneMapToSrgb(img.data(), 10, out.data(), ToneMapParams{-0.18f}));
        QVERIFY_THROWS_EXCEPTION(Error, toneMapToSrgb(img.data(), 10, out.data(), ToneMapParams{std::numeric_limits<float>::quiet_NaN()}));
        QVERIFY_THROWS_EXCEPTION(Error, toneMapToSrgb(nullptr, 10, out.data(), {}));
        toneMapToSrgb(nullptr, 0, nullptr, {});   // empty image: nothing to do
    }
    // The studio's picture of a film (toneMapFilm, written once for HostExec and the GPU's CudaExec) equals
    // the whole-image path of `sylva render` on the same film: composeMode, then toneMapToSrgb, then 8-bit
    // rounding; for each mode, with NaN and infinite pixels in the film, and the compare halves each equal
    // to their own mode's picture.
    void toneMapFilmEqualsWholeImagePath()
    {
        const int w = 301, h = 173;   // odd width: the compare split is not a multiple of anything
        Film film;
        film.width = w;
        film.height = h;
        film.pixels.resize(size_t(w) * h);
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 2.0f);
        for (SampleParts& p : film.pixels) {
            p.local = glm::vec3(u(rng), u(rng), u(rng)) * u(rng);
            p.indirect = glm::vec3(u(rng), u(rng), u(rng)) * 0.3f;
            p.albedo = glm::vec3(u(rng), u(rng), u(rng)) * 0.4f;
            p.skyCover = rng() % 5 == 0 ? u(rng) * 0.5f : 0.0f;
        }
        film.pixels[17].local.x = std::numeric_limits<float>::quiet_NaN();
        film.pixels[4000].indirect.y = std::numeric_limits<float>::infinity();
        const glm::vec3 sky(0.4f, 0.6f, 0.9f);
        const float key = 0.22f;
        auto reference = [&](RenderMode mode) {
            const std::vector<glm::vec3> lin = composeMode(film, mode, sky);
            std::vector<float> srgb(lin.size() * 3);
            toneMapToSrgb(reinterpret_cast<const float*>(lin.data()), lin.size(), srgb.data(), ToneMapParams{key});
            std::vector<uint32_t> px(lin.size());
            for (size_t i = 0; i < lin.size(); ++i) {
                uint32_t v = 255u << 24;
                for (int c = 0; c < 3; ++c) v |= uint32_t(std::clamp(srgb[i * 3 + c], 0.0f, 1.0f) * 255.0f + 0.5f) << (8 * c);
                px[i] = v;
            }
            return px;
        };
        const RenderMode modes[] = {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb};
        for (RenderMode left : modes) {
            const std::vector<uint32_t> want = reference(left);
            std::vector<uint32_t> got(want.size());
            double acc[kToneSums];
            toneMapFilm(HostExec{}, film.pixels.data(), w, h, left, left, sky, key, acc, got.data());
            QVERIFY2(got == want, qPrintable(QString("mode %1").arg(int(left))));
            for (RenderMode right : modes) {
                if (right == left) continue;
                const std::vector<uint32_t> other = reference(right);
                toneMapFilm(HostExec{}, film.pixels.data(), w, h, left, right, sky, key, acc, got.data());
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        const size_t i = size_t(y) * w + x;
                        if (got[i] != (x < w / 2 ? want[i] : other[i]))
                            QFAIL(qPrintable(QString("compare %1|%2 differs at %3,%4").arg(int(left)).arg(int(right)).arg(x).arg(y)));
                    }
            }
        }
    }

    // HostExec::sum adds in a fixed chunk order: the same bits as a serial sum over the same chunks,
    // whatever the thread count; n = 0 gives zeros.
    void hostSumIsChunkOrdered()
    {
        const size_t n = 3 * HostExec::kChunk + 123;
        std::vector<double> v(n);
        std::mt19937 rng(3);
        for (double& x : v) x = std::ldexp(double(rng()), -int(rng() % 40));
        struct Body {
            const double* v;
            void operator()(size_t i, double* t) const { t[0] = v[i]; t[1] = 1.0; }
        };
        double got[2] = {-1.0, -1.0};
        HostExec{}.sum<2>(n, Body{v.data()}, got);
        double want = 0.0;
        for (size_t c = 0; c * HostExec::kChunk < n; ++c) {
            double part = 0.0;
            for (size_t i = c * HostExec::kChunk; i < std::min(n, (c + 1) * HostExec::kChunk); ++i) part += v[i];
            want += part;
        }
        QCOMPARE(got[0], want);
        QCOMPARE(got[1], double(n));
        HostExec{}.sum<2>(0, Body{v.data()}, got);
        QCOMPARE(got[0], 0.0);
        QCOMPARE(got[1], 0.0);
    }
};

QTEST_APPLESS_MAIN(TestToneMap)
#include "tst_tonemap.moc"
