// The equal-time plot of `sylva study truth` (study_plot.h).
#include "pipeline/study/study_plot.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pipeline/io/atomic_file.h"

namespace sylva::study {

void writeErrorTimeSvg(const std::string& path, const std::vector<std::string>& names, const std::vector<std::vector<CurvePoint>>& cycles,
                       const std::vector<std::vector<CurvePoint>>& sylva, const std::vector<std::vector<CurvePoint>>& sylvaOnce)
{
    const double W = 640, H = 420, L = 70, R = 150, T = 20, B = 50;
    double t0 = 1e30, t1 = 0, e0 = 1e30, e1 = 0;
    for (const auto* set : {&cycles, &sylva, &sylvaOnce})
        for (const auto& v : *set)
            for (const CurvePoint& p : v) {
                t0 = std::min(t0, p.seconds), t1 = std::max(t1, p.seconds);
                e0 = std::min(e0, p.m.lum), e1 = std::max(e1, p.m.lum);
            }
    t0 = std::pow(10.0, std::floor(std::log10(t0))), t1 = std::pow(10.0, std::ceil(std::log10(t1)));
    e0 = std::pow(10.0, std::floor(std::log10(std::max(e0, 1e-4)))), e1 = std::pow(10.0, std::ceil(std::log10(e1)));
    auto X = [&](double t) { return L + (W - L - R) * std::log(t / t0) / std::log(t1 / t0); };
    auto Y = [&](double e) { return T + (H - T - B) * (1.0 - std::log(std::max(e, e0) / e0) / std::log(e1 / e0)); };
    std::ostringstream s;
    s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H << "' font-family='sans-serif' font-size='11'>\n";
    s << "<rect width='100%' height='100%' fill='white'/>\n";
    for (double t = t0; t <= t1 * 1.0001; t *= 10)
        s << "<line x1='" << X(t) << "' y1='" << T << "' x2='" << X(t) << "' y2='" << H - B << "' stroke='#ddd'/><text x='" << X(t)
          << "' y='" << H - B + 15 << "' text-anchor='middle'>" << t << "</text>\n";
    for (double e = e0; e <= e1 * 1.0001; e *= 10)
        s << "<line x1='" << L << "' y1='" << Y(e) << "' x2='" << W - R << "' y2='" << Y(e) << "' stroke='#ddd'/><text x='" << L - 5
          << "' y='" << Y(e) + 4 << "' text-anchor='end'>" << e << "</text>\n";
    s << "<text x='" << (L + W - R) / 2 << "' y='" << H - 10 << "' text-anchor='middle'>seconds per frame (wall clock, 2 cores)</text>\n";
    s << "<text transform='translate(15," << (T + H - B) / 2 << ") rotate(-90)' text-anchor='middle'>relative L2 of luminance vs converged Cycles</text>\n";
    const char* colors[] = {"#1f77b4", "#2ca02c", "#d62728", "#9467bd"};
    for (size_t k = 0; k < names.size(); ++k) {
        const char* col = colors[k % 4];
        s << "<polyline fill='none' stroke='" << col << "' stroke-width='1.5' points='";
        for (const CurvePoint& p : cycles[k]) s << X(p.seconds) << "," << Y(p.m.lum) << " ";
        s << "'/>\n";
        for (const CurvePoint& p : cycles[k]) s << "<circle cx='" << X(p.seconds) << "' cy='" << Y(p.m.lum) << "' r='3' fill='" << col << "'/>\n";
        for (const CurvePoint& p : sylva[k])
            s << "<rect x='" << X(p.seconds) - 3.5 << "' y='" << Y(p.m.lum) - 3.5 << "' width='7' height='7' fill='none' stroke='" << col
              << "' stroke-width='1.5'/>\n";
        for (const CurvePoint& p : sylvaOnce[k])
            s << "<rect x='" << X(p.seconds) - 3.5 << "' y='" << Y(p.m.lum) - 3.5 << "' width='7' height='7' fill='" << col << "'/>\n";
        const double ly = T + 15 + 45.0 * double(k);
        s << "<circle cx='" << W - R + 15 << "' cy='" << ly << "' r='3' fill='" << col << "'/><text x='" << W - R + 25 << "' y='" << ly + 4
          << "'>Cycles, " << names[k] << "</text>\n";
        s << "<rect x='" << W - R + 11.5 << "' y='" << ly + 10.5 << "' width='7' height='7' fill='none' stroke='" << col
          << "'/><text x='" << W - R + 25 << "' y='" << ly + 18 << "'>Sylva, " << names[k] << "</text>\n";
        s << "<rect x='" << W - R + 11.5 << "' y='" << ly + 25.5 << "' width='7' height='7' fill='" << col << "'/><text x='" << W - R + 25
          << "' y='" << ly + 33 << "'>Sylva once, " << names[k] << "</text>\n";
    }
    s << "</svg>\n";
    AtomicFile file(path, AtomicFile::Sync::No, "plot");
    file.write(s.str());
    file.commit();
}

} // namespace sylva::study
