// The equal-time plot of `sylva study truth` (study_plot.cpp): error against time on log-log axes, as SVG.
#pragma once

#include <string>
#include <vector>

#include "pipeline/study/study_image.h"

namespace sylva::study {

// One run on an error-time curve: its label, seconds per frame and its errors against the reference.
struct CurvePoint {
    std::string label;
    double seconds;
    Metrics m;
};

// Error against time on log-log axes: each scene's Cycles curve and Sylva points (`names`: the scenes; sylva
// hollow squares, sylvaOnce filled ones), one SVG at `path`. Throws Error when it cannot be written.
void writeErrorTimeSvg(const std::string& path, const std::vector<std::string>& names, const std::vector<std::vector<CurvePoint>>& cycles,
                       const std::vector<std::vector<CurvePoint>>& sylva, const std::vector<std::vector<CurvePoint>>& sylvaOnce);

} // namespace sylva::study
