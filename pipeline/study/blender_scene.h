// A Sylva scene as a Blender (Cycles) Python script: the ground truth of `sylva study truth`. Text only:
// Blender is never linked nor needed to write it (docs/ACCURACY.md "Ground truth: Cycles").
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/lb/leaf_optics.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"

namespace sylva::study {

// The leaf optics of an LB channel (core/lb/leaf_optics.h): the translucent colour the export gives leaves.
using lb::forwardShare;
using lb::LeafOptics;
using lb::leafOptics;

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

// Sylva's Phong term (specular ks, shininess n: ks x (r . v)^n x sunRadiance, sun only) as a GGX Glossy BSDF:
// Phong about the reflection vector is about Blinn 4n about the half vector, alpha^2 = 2 / (4n + 2); the colour
// 4 alpha^2 ks gives the same radiance at the mirror direction under a head-on sun (GGX's peak D / 4 = 1 /
// (4 pi alpha^2) per unit irradiance), roughness = sqrt(alpha) (Cycles squares it). What differs: the lobe's
// shape away from its peak, and Cycles' glossy also reflects sky and inter-reflected light.
struct BlenderGlossy {
    glm::vec3 color;
    double roughness;
};
BlenderGlossy blenderGlossy(const glm::vec3& specular, float shininess);

// Which lights and optics a script run uses; the script also takes them from its command line after
// "--" (--samples N --seed S --out FILE.exr --sun 0|1 --sky 0|1 --translucent 0|1 --bounces N --threads N), so
// one script serves a whole sample sweep (and, by --bounces, the scattering orders: 0 direct light only, 1 up
// to single scattering).
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
