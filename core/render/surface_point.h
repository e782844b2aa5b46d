// What the surface stage finds at a hit, whatever kind of surface was hit: what the lights and the
// integrator need of it (host and device).
#pragma once

#include <math.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

// The point, the normal facing the viewer, the material and the surface's own indirect light.
struct SurfacePoint {
    glm::vec3 p;             // camera-relative
    glm::vec3 ng;            // unit normal facing the viewer
    glm::vec3 viewDir;       // toward the camera
    glm::vec3 albedo;        // diffuse colour (times the texture)
    glm::vec3 specular;      // Phong lobe (meshes' materials; 0 elsewhere)
    float shininess;
    float extent;            // the hit's largest species-frame coordinate in world units (offsetPoint); 0 = ground
    glm::vec3 lighting;      // normalized LB photon density at the point (meshes)
    glm::vec3 indirectWeight; // what the surface makes of it (SpeciesRecord leafIndirect / barkIndirect; 1 on the ground)
    glm::vec3 indirect;      // the surface's indirect light as its kind computes it (meshes: LB; 0 elsewhere)
    glm::vec3 transmission;  // diffuse transmission through to the other side (leaves; 0 elsewhere): the path tracer's
    bool ground;             // Lambertian ground (plane, terrain, spheres): lit by the uniform sky's ambient
};

// The three parts a render mode combines (linear RGB): local = sun light only, indirect = LB
// indirect light (ground: sky light), albedo = the surface colour the indirect light multiplies
// (for the constant-ambient comparison), skyCover = share of samples that saw the sky. Beside them,
// for the render passes only (no mode reads them): normal = the unit surface normal facing the
// viewer (world orientation; 0 for the sky), averaged over a pixel's samples like the parts, and
// depth = the distance along the camera's forward axis to the surface, the nearest over the samples
// (kSkyDepth for the sky). background = the radiance of a Preetham or map sky where samples saw it
// (averaged like the parts; 0 for the constant sky, which composes as skyCover x its colour). A
// Preetham or map sky's light on surfaces (its virtual lights) is direct light: it is in `local`.
// 68 bytes.
struct SampleParts {
    glm::vec3 local;
    glm::vec3 indirect;
    glm::vec3 albedo;
    float skyCover;
    glm::vec3 normal;
    float depth;
    glm::vec3 background;
};

// The depth of a sample that saw the sky (Cycles' value for the background of its Z pass).
inline constexpr float kSkyDepth = 1e10f;

// Offset along the geometric normal, scaled to the magnitude of the coordinates the hit was computed
// from (no self-shadowing acne): camera-relative p and, for a mesh hit, `extent` = its species-frame
// point's largest coordinate in world units. No floor in metres: a 1 m floor lifted the shadow rays of
// a micrometre-sized scene clear of all its geometry (it lost every shadow).
SYLVA_HD SYLVA_INLINE glm::vec3 offsetPoint(const glm::vec3& p, const glm::vec3& ng, float extent = 0.0f)
{
    const float m = fmaxf(fmaxf(fmaxf(fabsf(p.x), fabsf(p.y)), fmaxf(fabsf(p.z), extent)), 1e-30f);
    return p + ng * (m * 2e-5f);
}

// What the surface reflects toward the viewer of a light arriving from unit direction wi with nl = ng . wi > 0,
// `radiance` in the renderer's units (albedo x radiance x cos at normal incidence): Lambertian, plus the
// material's Phong lobe on meshes.
SYLVA_HD SYLVA_INLINE glm::vec3 reflectedLight(const SurfacePoint& s, const glm::vec3& wi, float nl, const glm::vec3& radiance)
{
    if (s.ground) return s.albedo * radiance * nl;
    glm::vec3 c = s.albedo * nl;
    if (s.shininess > 0.0f && (s.specular.x > 0.0f || s.specular.y > 0.0f || s.specular.z > 0.0f)) {
        const glm::vec3 r = 2.0f * nl * s.ng - wi;
        const float vr = glm::dot(s.viewDir, r);
        if (vr > 0.0f) c += s.specular * powf(vr, s.shininess);
    }
    return c * radiance;
}

// The point shadow rays start from.
SYLVA_HD SYLVA_INLINE glm::vec3 shadowOrigin(const SurfacePoint& s) { return offsetPoint(s.p, s.ng, s.extent); }

} // namespace sylva
