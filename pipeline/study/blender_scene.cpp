// A Sylva scene as a Blender Python script (Cycles): mesh data as raw arrays, materials, lamp, world, camera.
#include "pipeline/study/blender_scene.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/base/error.h"
#include "core/lb/leaf_optics.h"
#include "core/render/render_scene.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/render_job.h"

namespace sylva::study {

namespace fs = std::filesystem;

glm::dvec3 toBlender(const glm::dvec3& p) { return {p.x, -p.z, p.y}; }

namespace {

// Row-major 4x4 from Blender-frame columns (x, y, z axes) and origin.
std::array<double, 16> fromColumns(const glm::dvec3& x, const glm::dvec3& y, const glm::dvec3& z, const glm::dvec3& o)
{
    return {x.x, y.x, z.x, o.x, x.y, y.y, z.y, o.y, x.z, y.z, z.z, o.z, 0, 0, 0, 1};
}

// A number as Python source text (9 significant digits: a float round-trips).
std::string pyNumber(double v)
{
    char b[40];
    std::snprintf(b, sizeof b, "%.9g", v);
    return b;
}

std::string vec(const glm::dvec3& v)
{
    std::string s(1, '(');
    s += pyNumber(v.x);
    s += ", ";
    s += pyNumber(v.y);
    s += ", ";
    s += pyNumber(v.z);
    return s + ")";
}

std::string matrixText(const std::array<double, 16>& m)
{
    std::string s = "(";
    for (int r = 0; r < 4; ++r) {
        s += "(";
        for (int c = 0; c < 4; ++c) s += pyNumber(m[size_t(r * 4 + c)]) + (c < 3 ? ", " : "");
        s += r < 3 ? "), " : ")";
    }
    return s + ")";
}

// A Python string literal (paths).
std::string pyString(const std::string& s)
{
    std::string out = "r'";
    for (char ch : s) {
        if (ch == '\'' || ch == '\\' || ch == '\n') throw Error(s + ": a path the Blender script cannot quote (quote, backslash or newline)");
        out += ch;
    }
    return out + "'";
}

template <typename T>
void writeArray(const std::string& path, const std::vector<T>& data)
{
    AtomicFile f(path, AtomicFile::Sync::No, "Blender mesh data");
    if (!data.empty()) f.write(data.data(), data.size() * sizeof(T));
    f.commit();
}

// A file-name-safe stem from a species name.
std::string stemOf(const std::string& name, size_t index)
{
    std::string s;
    for (char c : name) s += (std::isalnum(static_cast<unsigned char>(c)) ? c : '_');
    std::string out = "s";
    out += std::to_string(index);
    out += '_';
    return out + s;
}

} // namespace

std::array<double, 16> blenderCameraMatrix(const CameraDesc& c)
{
    const glm::dvec3 fwd = c.target - c.position;
    if (!(glm::length(fwd) > 0.0)) throw Error("camera: position and target coincide");
    const glm::dvec3 f = glm::normalize(fwd);
    const glm::dvec3 rr = glm::cross(f, glm::dvec3(c.up));
    if (!(glm::length(rr) > 1e-6)) throw Error("camera: up is parallel to the view direction");
    const glm::dvec3 right = glm::normalize(rr), up = glm::cross(right, f);
    return fromColumns(toBlender(right), toBlender(up), toBlender(-f), toBlender(c.position));
}

std::array<double, 16> blenderInstanceMatrix(const InstanceDesc& d)
{
    const glm::dmat3 r = rotationDeg(d.rotationDeg) * double(d.scale);
    return fromColumns(toBlender(r[0]), toBlender(r[1]), toBlender(r[2]), toBlender(d.position));
}

BlenderSun blenderSun(const glm::vec3& rad)
{
    const float m = std::max(rad.x, std::max(rad.y, rad.z));
    if (!(m > 0.0f)) return {glm::vec3(1.0f), 0.0};
    return {rad / m, M_PI * double(m)};
}

BlenderGlossy blenderGlossy(const glm::vec3& specular, float shininess)
{
    const double a2 = 2.0 / (4.0 * double(shininess) + 2.0);   // Blinn exponent 4n about the half vector
    return {glm::vec3(float(4.0 * a2)) * specular, std::sqrt(std::sqrt(a2))};
}

std::string writeBlenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& dir,
                              const BlenderOptions& o, const std::string& skyExr)
{
    if (scene.terrain.enabled()) throw Error("Blender export: a scene with a terrain is not supported (the ground plane only)");
    if (!scene.groups.empty()) throw Error("Blender export: instance groups are not supported (species instances only)");
    if (assets.size() != scene.species.size()) throw Error("Blender export: the species' assets are not loaded");
    if (scene.skyModel.analytic() && !scene.skyModel.hasColor() && skyExr.empty())
        throw Error("Blender export: a Preetham or map sky needs its equirectangular EXR (sylva sky -o FILE.exr)");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw Error(dir + ": cannot create the folder");
    const std::string base = fs::absolute(dir).string() + "/";

    std::ostringstream py;
    py << "# Written by sylva (pipeline/study/blender_scene.cpp): a Sylva scene for Cycles.\n"
          "# blender -b --factory-startup --python scene.py -- [--samples N] [--seed S] [--out FILE.exr] [--sun 0|1] [--sky 0|1] [--translucent 0|1] [--bounces N] [--ground 0|1] [--threads N]\n"
          "import bpy, sys, os, time\nfrom array import array\n"
          "from mathutils import Matrix\n"
          "argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []\n"
          "def arg(name, default):\n"
          "    return type(default)(argv[argv.index(name) + 1]) if name in argv else default\n";
    py << "SAMPLES = arg('--samples', " << o.samples << ")\nSEED = arg('--seed', " << o.seed << ")\nTHREADS = arg('--threads', "
       << o.threads << ")\nOUT = arg('--out', " << pyString(o.exrPath) << ")\nSUN_ON = arg('--sun', 1)\nSKY_ON = arg('--sky', 1)\nTRANS_ON = arg('--translucent', 1)\nGROUND_ON = arg('--ground', 1)\n";
    py << "DATA = " << pyString(base) << "\n";
    py << "LEAF_MAX = " << lb::kMaxLeafScattering << "   # a leaf scatters at most this share (core/lb/leaf_optics.h)\n";
    py << R"PY(
for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob, do_unlink=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'
cy = sc.cycles
cy.device = 'CPU'
cy.samples = SAMPLES
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.seed = SEED
cy.pixel_filter_type = 'BOX'
cy.filter_width = 1.0
cy.sample_clamp_direct = 0.0
cy.sample_clamp_indirect = 0.0
cy.light_sampling_threshold = 0.0
cy.caustics_reflective = False
cy.caustics_refractive = False
cy.blur_glossy = 0.0
)PY";
    py << "BOUNCES = arg('--bounces', " << o.bounces << ")\n";
    py << "cy.max_bounces = BOUNCES\ncy.diffuse_bounces = BOUNCES\ncy.transmission_bounces = BOUNCES\ncy.glossy_bounces = BOUNCES\n"
          "cy.volume_bounces = 0\ncy.transparent_max_bounces = " << o.transparentBounces << "\n";
    py << "sc.render.resolution_x = " << scene.render.width << "\nsc.render.resolution_y = " << scene.render.height << "\n";
    py << R"PY(sc.render.resolution_percentage = 100
sc.render.pixel_aspect_x = 1.0
sc.render.pixel_aspect_y = 1.0
sc.render.film_transparent = False
sc.render.threads_mode = 'FIXED'
sc.render.threads = THREADS
sc.render.use_persistent_data = False
sc.view_settings.view_transform = 'Standard'
sc.view_settings.look = 'None'
sc.view_settings.exposure = 0.0
sc.view_settings.gamma = 1.0
im = sc.render.image_settings
im.file_format = 'OPEN_EXR_MULTILAYER'
im.color_depth = '32'
im.exr_codec = 'ZIP'
vl = sc.view_layers[0]
for p in ('use_pass_diffuse_direct', 'use_pass_diffuse_indirect', 'use_pass_diffuse_color',
          'use_pass_transmission_direct', 'use_pass_transmission_indirect', 'use_pass_transmission_color',
          'use_pass_environment'):
    setattr(vl, p, True)

def node(nt, kind, **props):
    n = nt.nodes.new(kind)
    for k, v in props.items():
        setattr(n, k, v)
    return n

def image(path, colorspace):
    img = bpy.data.images.load(DATA + path, check_existing=True)
    img.colorspace_settings.name = colorspace
    return img

# Sylva's surface material: kd = diffuse x texture (sRGB decoded, bilinear, wrapped); leaves add
# diffuse transmission kd x ratio, capped at LEAF_MAX - kd (translucent BSDF); a cut-out (nearest texel, opaque where alpha >= 0.5)
# lets the ray through as a transparent BSDF.
# Sylva's Phong term ks x (r . v)^n x sunRadiance (sun only) as a GGX Glossy BSDF of the same peak radiance
# and about the same lobe: Phong n about the reflection vector is Blinn n' = 4n about the half vector, alpha^2 =
# 2 / (n' + 2), colour 4 alpha^2 ks (spec, roughness = sqrt(alpha) already computed by the export).
def material(name, diffuse, leaf, ratio, color_png, mask_png, spec=(0.0, 0.0, 0.0), roughness=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = node(nt, 'ShaderNodeOutputMaterial')
    kd = node(nt, 'ShaderNodeRGB')
    kd.outputs[0].default_value = (diffuse[0], diffuse[1], diffuse[2], 1.0)
    col = kd.outputs[0]
    if color_png:
        tex = node(nt, 'ShaderNodeTexImage', interpolation='Linear', extension='REPEAT')
        tex.image = image(color_png, 'sRGB')
        mul = node(nt, 'ShaderNodeVectorMath', operation='MULTIPLY')
        nt.links.new(kd.outputs[0], mul.inputs[0])
        nt.links.new(tex.outputs['Color'], mul.inputs[1])
        col = mul.outputs[0]
    dif = node(nt, 'ShaderNodeBsdfDiffuse')
    dif.inputs['Roughness'].default_value = 0.0
    nt.links.new(col, dif.inputs['Color'])
    surf = dif.outputs[0]
    if leaf:
        tr = node(nt, 'ShaderNodeVectorMath', operation='MULTIPLY')
        nt.links.new(col, tr.inputs[0])
        tr.inputs[1].default_value = (ratio[0] * TRANS_ON, ratio[1] * TRANS_ON, ratio[2] * TRANS_ON)
        room = node(nt, 'ShaderNodeVectorMath', operation='SUBTRACT')   # energy: kd + transmission <= LEAF_MAX
        room.inputs[0].default_value = (LEAF_MAX, LEAF_MAX, LEAF_MAX)
        nt.links.new(col, room.inputs[1])
        cap = node(nt, 'ShaderNodeVectorMath', operation='MINIMUM')
        nt.links.new(tr.outputs[0], cap.inputs[0])
        nt.links.new(room.outputs[0], cap.inputs[1])
        pos = node(nt, 'ShaderNodeVectorMath', operation='MAXIMUM')
        nt.links.new(cap.outputs[0], pos.inputs[0])
        pos.inputs[1].default_value = (0.0, 0.0, 0.0)
        tl = node(nt, 'ShaderNodeBsdfTranslucent')
        nt.links.new(pos.outputs[0], tl.inputs['Color'])
        add = node(nt, 'ShaderNodeAddShader')
        nt.links.new(surf, add.inputs[0])
        nt.links.new(tl.outputs[0], add.inputs[1])
        surf = add.outputs[0]
    if max(spec) > 0.0:
        gl = node(nt, 'ShaderNodeBsdfGlossy', distribution='GGX')
        gl.inputs['Color'].default_value = (spec[0], spec[1], spec[2], 1.0)
        gl.inputs['Roughness'].default_value = roughness
        add2 = node(nt, 'ShaderNodeAddShader')
        nt.links.new(surf, add2.inputs[0])
        nt.links.new(gl.outputs[0], add2.inputs[1])
        surf = add2.outputs[0]
    if mask_png:
        mt = node(nt, 'ShaderNodeTexImage', interpolation='Closest', extension='REPEAT')
        mt.image = image(mask_png, 'Non-Color')
        gt = node(nt, 'ShaderNodeMath', operation='GREATER_THAN')
        nt.links.new(mt.outputs['Color'], gt.inputs[0])
        gt.inputs[1].default_value = 0.5
        tp = node(nt, 'ShaderNodeBsdfTransparent')
        mix = node(nt, 'ShaderNodeMixShader')
        nt.links.new(gt.outputs[0], mix.inputs['Fac'])
        nt.links.new(tp.outputs[0], mix.inputs[1])
        nt.links.new(surf, mix.inputs[2])
        surf = mix.outputs[0]
        m.blend_method = 'CLIP'
    nt.links.new(surf, out.inputs['Surface'])
    return m

# A species mesh exactly as Sylva holds it (species frame, +Y up: the instances carry the axis change).
def species(name, stem, materials):
    def load(ext, code):
        a = array(code)
        path = DATA + stem + ext
        with open(path, 'rb') as fh:
            a.fromfile(fh, os.path.getsize(path) // a.itemsize)
        if sys.byteorder != 'little':
            a.byteswap()
        return a
    P, N, UV, T, M = load('.pos.f32', 'f'), load('.nrm.f32', 'f'), load('.uvl.f32', 'f'), load('.tri.u32', 'i'), load('.mat.u32', 'i')
    nv, nt = len(P) // 3, len(T) // 3
    me = bpy.data.meshes.new(name)
    me.vertices.add(nv)
    me.vertices.foreach_set('co', P)
    me.loops.add(len(T))
    me.loops.foreach_set('vertex_index', T)
    me.polygons.add(nt)
    me.polygons.foreach_set('loop_start', array('i', range(0, len(T), 3)))
    me.polygons.foreach_set('loop_total', array('i', [3]) * nt)
    me.polygons.foreach_set('material_index', M)
    me.polygons.foreach_set('use_smooth', [True] * nt)
    if len(UV) == 2 * len(T):
        uvl = me.uv_layers.new(name='UVMap')
        uvl.data.foreach_set('uv', UV)
    me.update(calc_edges=True)
    if len(N) == len(P):
        me.use_auto_smooth = True
        me.normals_split_custom_set_from_vertices([N[i:i + 3] for i in range(0, len(N), 3)])
    for m in materials:
        me.materials.append(m)
    ob = bpy.data.objects.new(name, me)
    coll = bpy.data.collections.new(name)
    coll.objects.link(ob)
    return coll

def place(coll, name, matrix):
    e = bpy.data.objects.new(name, None)
    e.instance_type = 'COLLECTION'
    e.instance_collection = coll
    e.matrix_world = Matrix(matrix)
    sc.collection.objects.link(e)

)PY";

    // Species: mesh arrays, textures, materials.
    for (size_t s = 0; s < scene.species.size(); ++s) {
        const SpeciesDesc& sp = scene.species[s];
        const SpeciesAssets& a = assets[s];
        const TriangleMesh& m = a.mesh;
        const std::string stem = stemOf(sp.name, s);
        std::vector<glm::vec3> nrm = m.normals, pos = m.positions;
        std::vector<glm::vec2> uv = m.uvs;
        std::vector<glm::uvec3> tri = m.triangles;
        std::vector<uint32_t> mat = m.triangleMaterial;
        if (mat.size() != tri.size()) mat.assign(tri.size(), 0u);
        writeArray(base + stem + ".pos.f32", pos);
        writeArray(base + stem + ".nrm.f32", nrm);
        std::vector<glm::vec2> loopUv;   // per triangle corner (Blender's loops)
        if (uv.size() == pos.size()) {
            loopUv.reserve(tri.size() * 3);
            for (const glm::uvec3& t : tri)
                for (int c = 0; c < 3; ++c) loopUv.push_back(uv[t[c]]);
        }
        writeArray(base + stem + ".uvl.f32", loopUv);
        writeArray(base + stem + ".tri.u32", tri);
        writeArray(base + stem + ".mat.u32", mat);
        const LeafOptics lo = leafOptics(sp.lighting);
        std::string mats = "[";
        const size_t nm = std::max<size_t>(m.materials.size(), 1);
        for (size_t k = 0; k < nm; ++k) {
            Material mt;
            if (k < m.materials.size()) mt = m.materials[k];
            std::string colorPng, maskPng;
            if (k < a.diffuse.size() && !a.diffuse[k].empty()) {
                colorPng = stem + "_m" + std::to_string(k) + "_color.png";
                writeImage(base + colorPng, a.diffuse[k], 3);
            }
            if (k < a.cutout.size() && !a.cutout[k].empty()) {
                const ImageRgba& c = a.cutout[k];
                ImageRgba mask(c.width, c.height);
                bool anyClear = false;
                for (size_t p = 0; p < size_t(c.width) * size_t(c.height); ++p) {
                    const float v = c.pixels[p * 4 + 3] >= 0.5f ? 1.0f : 0.0f;
                    anyClear = anyClear || v == 0.0f;
                    for (int ch = 0; ch < 3; ++ch) mask.pixels[p * 4 + size_t(ch)] = v;
                    mask.pixels[p * 4 + 3] = 1.0f;
                }
                if (anyClear) {   // the renderer drops an all-opaque cut-out too (addCutout)
                    maskPng = stem + "_m" + std::to_string(k) + "_mask.png";
                    writeImage(base + maskPng, mask, 3);
                }
            }
            mats += "material(" + pyString(stem + "_" + (mt.name.empty() ? std::string("default") : mt.name)) + ", " +
                    vec(glm::dvec3(mt.diffuse)) + ", " + (mt.isLeaf ? "True" : "False") + ", " + vec(glm::dvec3(lo.ratio)) + ", " +
                    (colorPng.empty() ? "None" : pyString(colorPng)) + ", " + (maskPng.empty() ? "None" : pyString(maskPng));
            if (mt.shininess > 0.0f && (mt.specular.x > 0.0f || mt.specular.y > 0.0f || mt.specular.z > 0.0f)) {
                const BlenderGlossy gl = blenderGlossy(mt.specular, mt.shininess);
                mats += ", " + vec(glm::dvec3(gl.color)) + ", " + pyNumber(gl.roughness);
            }
            mats += "), ";
        }
        mats += "]";
        py << "coll" << s << " = species(" << pyString(sp.name) << ", " << pyString(stem) << ", " << mats << ")\n";
    }
    // Instances.
    py << "INSTANCES = [\n";
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.group != kNoGroup) throw Error("Blender export: instance groups are not supported");
        if (d.species >= scene.species.size()) throw Error("Blender export: an instance names a species the scene lacks");
        py << " (" << d.species << ", " << matrixText(blenderInstanceMatrix(d)) << "),\n";
    }
    py << "]\n";
    py << "COLLS = [";
    for (size_t s = 0; s < scene.species.size(); ++s) py << "coll" << s << ", ";
    py << "]\nfor i, (s, mtx) in enumerate(INSTANCES):\n    place(COLLS[s], 'instance%d' % i, mtx)\n";

    // Ground: Lambertian plane at the ground height (Sylva's is infinite; 80 km is beyond every view here).
    if (scene.ground.enabled) {
        py << "gm = bpy.data.meshes.new('ground')\nH = 40000.0\nZ = " << pyNumber(scene.ground.height)
           << "\ngm.from_pydata([(-H, -H, Z), (H, -H, Z), (H, H, Z), (-H, H, Z)], [], [(0, 1, 2, 3)])\n"
              "gmat = material('ground', "
           << vec(glm::dvec3(scene.ground.color))
           << ", False, (0, 0, 0), None, None)\ngm.materials.append(gmat)\ngo = bpy.data.objects.new('ground', gm)\n"
              "if GROUND_ON:\n    sc.collection.objects.link(go)\n";
    }
    // Sun lamp: the same direction, colour and irradiance (blenderSun); a point-like sun (angle 0).
    {
        const FrameSun fs = frameSun(scene, sunRadiance(scene.sun));   // a Preetham or map sky's own sun, as the renderer's
        const BlenderSun bs = blenderSun(fs.radiance);
        const glm::dvec3 z = glm::normalize(toBlender(glm::dvec3(fs.direction)));   // lamp shines along -z
        glm::dvec3 x = glm::cross(glm::dvec3(0, 0, 1), z);
        if (glm::length(x) < 1e-9) x = glm::dvec3(1, 0, 0);
        x = glm::normalize(x);
        const glm::dvec3 y = glm::cross(z, x);
        py << "sund = bpy.data.lights.new('sun', 'SUN')\nsund.color = " << vec(glm::dvec3(bs.color)) << "\nsund.energy = "
           << pyNumber(bs.strength) << " * SUN_ON\nsund.angle = 0.0\n";
        py << "sund.cycles.cast_shadow = True\nsuno = bpy.data.objects.new('sun', sund)\nsuno.matrix_world = Matrix("
           << matrixText(fromColumns(x, y, z, glm::dvec3(0.0, 0.0, 100.0))) << ")\nsc.collection.objects.link(suno)\n";
        py << "try:\n    vl.lightgroups.add(name='sun')\n    vl.lightgroups.add(name='sky')\n    suno.lightgroup = 'sun'\n"
              "except Exception as e:\n    print('no light groups:', e)\n";
    }
    // World: the constant sky's radiance (strength 1: a Lambertian ground under it shows albedo x sky, as in
    // Sylva), or the equirectangular map of a Preetham or map sky (nearest pixel, Sylva's orientation).
    py << "w = bpy.data.worlds.new('sky')\nsc.world = w\nw.use_nodes = True\nwn = w.node_tree\nwn.nodes.clear()\n"
          "bg = node(wn, 'ShaderNodeBackground')\nwo = node(wn, 'ShaderNodeOutputWorld')\nwn.links.new(bg.outputs[0], wo.inputs['Surface'])\n"
          "bg.inputs['Strength'].default_value = 1.0 * SKY_ON\n";
    if (skyExr.empty()) {
        py << "bg.inputs['Color'].default_value = (" << pyNumber(scene.sky.x) << ", " << pyNumber(scene.sky.y) << ", " << pyNumber(scene.sky.z)
           << ", 1.0)\n";
    } else {
        // Sylva's map: u = 1/2 - atan2(x, z) / (2 pi) (Sylva frame), v = acos(y) / pi from the top row. Cycles':
        // u = 1/2 - atan2(Y, X) / (2 pi) of the Blender direction (X, Y, Z) = (x, -z, y), so it is looked up
        // at (-Y, X, Z) = (z, x, y): the same texel.
        py << "et = node(wn, 'ShaderNodeTexEnvironment', interpolation='Closest', projection='EQUIRECTANGULAR')\n"
              "et.image = bpy.data.images.load("
           << pyString(fs::absolute(skyExr).string())
           << ")\net.image.colorspace_settings.name = 'Linear'\n"
              "tc = node(wn, 'ShaderNodeTexCoord')\nsx = node(wn, 'ShaderNodeSeparateXYZ')\ncx = node(wn, 'ShaderNodeCombineXYZ')\n"
              "neg = node(wn, 'ShaderNodeMath', operation='MULTIPLY')\nneg.inputs[1].default_value = -1.0\n"
              "wn.links.new(tc.outputs['Generated'], sx.inputs[0])\nwn.links.new(sx.outputs['X'], cx.inputs['Y'])\n"
              "wn.links.new(sx.outputs['Y'], neg.inputs[0])\nwn.links.new(neg.outputs[0], cx.inputs['X'])\n"
              "wn.links.new(sx.outputs['Z'], cx.inputs['Z'])\n"
              "wn.links.new(cx.outputs[0], et.inputs['Vector'])\nwn.links.new(et.outputs['Color'], bg.inputs['Color'])\n";
    }
    py << "try:\n    w.lightgroup = 'sky'\nexcept Exception:\n    pass\n";
    // Camera: the same position, target, up and vertical field of view; the aspect from the resolution.
    {
        const CameraDesc& c = scene.camera;
        py << "camd = bpy.data.cameras.new('camera')\ncamd.sensor_fit = 'VERTICAL'\ncamd.angle_y = " << pyNumber(double(c.fovY) * M_PI / 180.0)
           << "\ncamd.clip_start = 0.01\ncamd.clip_end = 1.0e6\ncamo = bpy.data.objects.new('camera', camd)\ncamo.matrix_world = Matrix("
           << matrixText(blenderCameraMatrix(c)) << ")\nsc.collection.objects.link(camo)\nsc.camera = camo\n";
    }
    py << R"PY(
sc.render.filepath = OUT
sc.render.use_file_extension = False
t0 = time.time()
bpy.ops.render.render(write_still=True)
print('SYLVA_CYCLES_SECONDS=%.6f' % (time.time() - t0))
print('SYLVA_CYCLES_SAMPLES=%d' % SAMPLES)
)PY";
    const std::string scriptPath = base + "scene.py";
    AtomicFile f(scriptPath, AtomicFile::Sync::No, "Blender script");
    f.write(py.str());
    f.commit();
    return scriptPath;
}

} // namespace sylva::study
