// A Sylva scene as a Blender (Cycles) Python script: the ground truth of `sylva study truth`. Text only:
// Blender is never linked nor needed to write it (docs/ACCURACY.md "Ground truth: Cycles").
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/render/render_scene.h"
#include "core/scene/scene.h"

namespace sylva::study {

// The leaf's surface optics that one LB channel (sigma_a, sigma_s, g) stands for: of the light a leaf
// scatters, the Henyey-Greenstein phase sends forwardShare(g) through the leaf (transmission) and the
// rest back (reflection); the single-scattering albedo sigma_s / (sigma_a + sigma_s) is their sum.
// forwardShare(g) = integral of the HG phase over the forward hemisphere
//                 = (1 + g) / (2 g) - (1 - g^2) / (2 g sqrt(1 + g^2)), 1/2 at g = 0.
double forwardShare(double g);
struct LeafOptics {
    glm::vec3 albedo;        // sigma_s / sigma_t per channel
    glm::vec3 reflectance;   // albedo x (1 - forwardShare)
    glm::vec3 transmittance; // albedo x forwardShare
    glm::vec3 ratio;         // transmittance / reflectance: the translucent colour per unit of diffuse colour
};
LeafOptics leafOptics(const lb::LbParams& params);

// Sylva (+Y up) to Blender (+Z up) world coordinates: (x, y, z) -> (x, -z, y), a proper rotation.
glm::dvec3 toBlender(const glm::dvec3& p);

// The camera's world matrix in Blender's frame and conventions (looks along local -Z, up = local +Y),
// row-major 4x4, from the same basis Sylva's camera rays use (makeCamera).
std::array<double, 16> blenderCameraMatrix(const CameraDesc& camera);
// An instance's world matrix in Blender's frame: C x (translate x R x scale), row-major 4x4.
std::array<double, 16> blenderInstanceMatrix(const InstanceDesc& instance);

// The sun lamp: colour (max channel 1) and strength (W/m^2 in Cycles' units) such that a white
// Lambertian surface facing it shows Sylva's local term, albedo x sunRadiance x cos (Cycles: strength x
// colour x cos / pi).
struct BlenderSun {
    glm::vec3 color;
    double strength;
};
BlenderSun blenderSun(const glm::vec3& sunRadiance);

// Which lights and optics a script run uses; the script also takes them from its command line after
// "--" (--samples N --seed S --out FILE.exr --sun 0|1 --sky 0|1 --threads N), so one script serves a
// whole sample sweep.
struct BlenderOptions {
    int samples = 64;
    int seed = 0;
    int threads = 2;
    std::string exrPath = "cycles.exr";   // multi-layer EXR: Combined plus the passes (Diff/Trans Dir/Ind/Col, Env)
    int bounces = 64;                     // diffuse, transmission and total bounce limits
    int transparentBounces = 256;         // alpha cut-outs: each leaf card passed is a transparent bounce
};

// Writes the scene for Blender into dir: per species NAME.pos.f32, NAME.nrm.f32 (per vertex, little-endian
// float32), NAME.uvl.f32 (per triangle corner), NAME.tri.u32 (3 per triangle), NAME.mat.u32 (per triangle), and per
// textured material NAME_mK_color.png (the colour texture as Sylva reads it, sRGB) and
// NAME_mK_mask.png (the cut-out, 1 = opaque, Sylva's 0.5 threshold applied), then scene.py (returned:
// its path). Meshes are as Sylva reads them (imported or grown, cleaned); instances become collection
// instances; the ground an 80 km plane; the constant sky the world colour, a Preetham or map sky an
// equirectangular EXR the caller wrote (skyExr, radiance per pixel; empty for the constant sky).
// Throws Error on what the script cannot express (terrain, instance groups) or a failed write.
std::string writeBlenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& dir,
                              const BlenderOptions& options, const std::string& skyExr = {});

} // namespace sylva::study
