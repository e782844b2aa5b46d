// LDR-FLIP from the paper: colour pipeline (YCxCz, contrast-sensitivity filters, Hunt, HyAB) and feature
// pipeline (edges and points of the achromatic channel), combined as dE_c ^ (1 - dE_f).
#include "pipeline/study/flip.h"

#include <algorithm>
#include <cmath>

#include "core/base/error.h"

namespace sylva::study {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kQc = 0.7, kQf = 0.5, kPc = 0.4, kPt = 0.95;
const glm::dvec3 kWhite{0.950428545377181, 1.0, 1.08890037079813};   // XYZ of linear sRGB (1, 1, 1)

double decode(double c)
{
    c = std::clamp(c, 0.0, 1.0);
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

glm::dvec3 linearToXyz(const glm::dvec3& c)
{
    return {0.4124564 * c.x + 0.3575761 * c.y + 0.1804375 * c.z, 0.2126729 * c.x + 0.7151522 * c.y + 0.0721750 * c.z,
            0.0193339 * c.x + 0.1191920 * c.y + 0.9503041 * c.z};
}

glm::dvec3 xyzToLinear(const glm::dvec3& x)
{
    return {3.2404542 * x.x - 1.5371385 * x.y - 0.4985314 * x.z, -0.9692660 * x.x + 1.8760108 * x.y + 0.0415560 * x.z,
            0.0556434 * x.x - 0.2040259 * x.y + 1.0572252 * x.z};
}

glm::dvec3 xyzToYcxcz(const glm::dvec3& x)
{
    const glm::dvec3 n = x / kWhite;
    return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}

glm::dvec3 ycxczToXyz(const glm::dvec3& c)
{
    const double y = (c.x + 16.0) / 116.0;
    return glm::dvec3(c.y / 500.0 + y, y, y - c.z / 200.0) * kWhite;
}

double labF(double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; }

glm::dvec3 xyzToLab(const glm::dvec3& x)
{
    const glm::dvec3 n = x / kWhite;
    const double fx = labF(n.x), fy = labF(n.y), fz = labF(n.z);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

glm::dvec3 hunt(const glm::dvec3& lab) { return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z}; }

double hyab(const glm::dvec3& a, const glm::dvec3& b)
{
    return std::fabs(a.x - b.x) + std::sqrt((a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

double cmax()
{
    static const double c = std::pow(hyab(hunt(xyzToLab(linearToXyz({0, 1, 0}))), hunt(xyzToLab(linearToXyz({0, 0, 1})))), kQc);
    return c;
}

double remap(double hyabValue)
{
    const double e = std::pow(hyabValue, kQc), cm = cmax(), pccm = kPc * cm;
    return e < pccm ? kPt / pccm * e : kPt + (e - pccm) / (cm - pccm) * (1.0 - kPt);
}

// Separable-in-effect 2D convolution of one channel with a (2r+1)^2 kernel, edges clamped.
std::vector<double> convolve(const std::vector<double>& img, int w, int h, const std::vector<double>& k, int r)
{
    std::vector<double> out(img.size(), 0.0);
    const int n = 2 * r + 1;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0.0;
            for (int dy = -r; dy <= r; ++dy) {
                const int yy = std::clamp(y + dy, 0, h - 1);
                for (int dx = -r; dx <= r; ++dx) {
                    const int xx = std::clamp(x + dx, 0, w - 1);
                    s += k[size_t((dy + r) * n + (dx + r))] * img[size_t(yy) * size_t(w) + size_t(xx)];
                }
            }
            out[size_t(y) * size_t(w) + size_t(x)] = s;
        }
    return out;
}

// The contrast sensitivity functions as spatial Gaussians (the paper's Table: achromatic, red-green,
// blue-yellow), each normalized to sum 1, on a common radius.
struct Csf {
    std::vector<double> k[3];
    int r = 0;
};

Csf csfKernels(double ppd)
{
    const double a1[3] = {1.0, 1.0, 34.1}, b1[3] = {0.0047, 0.0053, 0.04}, a2[3] = {0.0, 0.0, 13.5}, b2[3] = {1e-5, 1e-5, 0.025};
    const double bmax = 0.04;
    Csf c;
    c.r = int(std::ceil(3.0 * std::sqrt(bmax / (2.0 * kPi * kPi)) * ppd));
    const int n = 2 * c.r + 1;
    const double dx = 1.0 / ppd;
    for (int ch = 0; ch < 3; ++ch) {
        c.k[ch].resize(size_t(n * n));
        double sum = 0.0;
        for (int y = -c.r; y <= c.r; ++y)
            for (int x = -c.r; x <= c.r; ++x) {
                const double z = (x * dx) * (x * dx) + (y * dx) * (y * dx);
                const double g = a1[ch] * std::sqrt(kPi / b1[ch]) * std::exp(-kPi * kPi * z / b1[ch]) +
                                 a2[ch] * std::sqrt(kPi / b2[ch]) * std::exp(-kPi * kPi * z / b2[ch]);
                c.k[ch][size_t((y + c.r) * n + (x + c.r))] = g;
                sum += g;
            }
        for (double& v : c.k[ch]) v /= sum;
    }
    return c;
}

// Edge (first derivative) and point (second derivative) detectors along x: Gaussian of sd = 0.5 x 0.082
// degrees; positive and negative weights each normalized to sum 1 in magnitude. Along y: the transpose.
void featureKernels(double ppd, std::vector<double>& edge, std::vector<double>& point, int& r)
{
    const double sd = 0.5 * 0.082 * ppd;
    r = int(std::ceil(3.0 * sd));
    const int n = 2 * r + 1;
    edge.assign(size_t(n * n), 0.0);
    point.assign(size_t(n * n), 0.0);
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
            const double g = std::exp(-(x * x + y * y) / (2.0 * sd * sd));
            edge[size_t((y + r) * n + (x + r))] = -x * g;
            point[size_t((y + r) * n + (x + r))] = (x * x / (sd * sd) - 1.0) * g;
        }
    for (std::vector<double>* k : {&edge, &point}) {
        double pos = 0.0, neg = 0.0;
        for (double v : *k) (v > 0.0 ? pos : neg) += v;
        for (double& v : *k) v = v > 0.0 ? v / pos : (v < 0.0 ? v / -neg : 0.0);
    }
}

std::vector<double> transpose(const std::vector<double>& k, int r)
{
    const int n = 2 * r + 1;
    std::vector<double> t(k.size());
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) t[size_t(x * n + y)] = k[size_t(y * n + x)];
    return t;
}

} // namespace

glm::dvec3 srgbToLab(const glm::dvec3& s) { return xyzToLab(linearToXyz({decode(s.x), decode(s.y), decode(s.z)})); }

double flipColorError(const glm::dvec3& a, const glm::dvec3& b) { return remap(hyab(hunt(srgbToLab(a)), hunt(srgbToLab(b)))); }

FlipResult flip(const std::vector<glm::vec3>& ref, const std::vector<glm::vec3>& test, int w, int h, double ppd)
{
    const size_t np = size_t(w) * size_t(h);
    if (w <= 0 || h <= 0 || ref.size() != np || test.size() != np) throw Error("FLIP: the pictures differ in size");
    const Csf csf = csfKernels(ppd);
    std::vector<double> edgeX, pointX;
    int fr = 0;
    featureKernels(ppd, edgeX, pointX, fr);
    const std::vector<double> edgeY = transpose(edgeX, fr), pointY = transpose(pointX, fr);

    struct Prepared {
        std::vector<glm::dvec3> lab;    // filtered, Hunt-adjusted
        std::vector<double> edge, point;
    };
    auto prepare = [&](const std::vector<glm::vec3>& img) {
        std::vector<double> ch[3];
        for (auto& c : ch) c.resize(np);
        std::vector<double> yNorm(np);
        for (size_t p = 0; p < np; ++p) {
            const glm::dvec3 o = xyzToYcxcz(linearToXyz({decode(img[p].x), decode(img[p].y), decode(img[p].z)}));
            ch[0][p] = o.x;
            ch[1][p] = o.y;
            ch[2][p] = o.z;
            yNorm[p] = (o.x + 16.0) / 116.0;
        }
        Prepared out;
        for (int c = 0; c < 3; ++c) ch[c] = convolve(ch[c], w, h, csf.k[c], csf.r);
        out.lab.resize(np);
        for (size_t p = 0; p < np; ++p) {
            glm::dvec3 lin = xyzToLinear(ycxczToXyz({ch[0][p], ch[1][p], ch[2][p]}));
            lin = glm::clamp(lin, glm::dvec3(0.0), glm::dvec3(1.0));
            out.lab[p] = hunt(xyzToLab(linearToXyz(lin)));
        }
        const std::vector<double> ex = convolve(yNorm, w, h, edgeX, fr), ey = convolve(yNorm, w, h, edgeY, fr);
        const std::vector<double> px = convolve(yNorm, w, h, pointX, fr), py = convolve(yNorm, w, h, pointY, fr);
        out.edge.resize(np);
        out.point.resize(np);
        for (size_t p = 0; p < np; ++p) {
            out.edge[p] = std::hypot(ex[p], ey[p]);
            out.point[p] = std::hypot(px[p], py[p]);
        }
        return out;
    };
    const Prepared a = prepare(ref), b = prepare(test);
    FlipResult r;
    r.map.resize(np);
    double sum = 0.0;
    for (size_t p = 0; p < np; ++p) {
        const double dc = remap(hyab(a.lab[p], b.lab[p]));
        const double df = std::pow(std::max(std::fabs(a.edge[p] - b.edge[p]), std::fabs(a.point[p] - b.point[p])) / std::sqrt(2.0), kQf);
        const double e = std::pow(dc, 1.0 - df);
        r.map[p] = float(e);
        sum += e;
    }
    r.mean = sum / double(np);
    return r;
}

} // namespace sylva::study
