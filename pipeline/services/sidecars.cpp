// Reference grid file names and sidecar parameters (sidecars.h).
#include "pipeline/services/sidecars.h"

#include <sstream>

#include "pipeline/lighting_job.h"

namespace sylva {

std::string standardErrorPath(const std::string& meanPath)
{
    const std::string ext = ".npy";
    if (meanPath.size() > ext.size() && meanPath.compare(meanPath.size() - ext.size(), ext.size(), ext) == 0)
        return meanPath.substr(0, meanPath.size() - ext.size()) + ".stderr.npy";
    return meanPath + ".stderr.npy";
}

std::string referenceParamsJson(const lb::LbParams& params, const std::string& preset, const ReferenceSettings& settings,
                                ReferenceQuantity quantity)
{
    std::ostringstream json;
    json.precision(9);
    json << "{\"solver\":\"reference\"," << opticsJsonMembers(params, preset) << ",\"paths\":" << settings.paths
         << ",\"seed\":" << settings.seed << ",\"max_bounces\":" << settings.maxBounces << ",\"incidence\":\""
         << (settings.incidence == Incidence::Collimated ? "collimated" : "lattice") << "\",\"quantity\":\""
         << (quantity == ReferenceQuantity::Mean ? "mean fluence" : "standard error of the mean") << "\"}";
    return json.str();
}

} // namespace sylva
