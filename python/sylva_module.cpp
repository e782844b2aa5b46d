// `import sylva`: scenes (load, edit, save), species (grow, import), and the light, render and export jobs of the
// command line and the studio as Python calls, with progress callbacks and cancellation; grids, meshes and films
// as NumPy arrays over the C++ buffers (no copies). docs/PYTHON.md is the user's guide.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <dlfcn.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/render/render_cpu.h"
#include "core/scene/quality.h"
#include "core/scene/scene.h"
#include "pipeline/backend_select.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/io/image_module.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/render_passes.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/scene/scene_species.h"
#include "pipeline/services/exports.h"
#include "pipeline/services/gltf_export.h"
#include "python/job_context.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace sylva::python {
namespace {

// The OpenImageIO module installed relative to this module's file (pictures are written through it).
void findImageModule()
{
#ifdef SYLVA_IMAGE_MODULE_FROM_PYTHON
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&findImageModule), &info) && info.dli_fname)
        image_module::addSearchPath((std::filesystem::path(info.dli_fname).parent_path() / SYLVA_IMAGE_MODULE_FROM_PYTHON).string());
#endif
}

// ---- arrays over C++ buffers ----

// A NumPy array of `shape` over the elements of `owner`'s vector `data` (of T, whose components are Scalar): the
// array's base keeps the owner alive, nothing is copied.
template <class Scalar, class Owner, class T>
py::array arrayOver(const std::shared_ptr<Owner>& owner, const std::vector<T>& data, std::vector<py::ssize_t> shape)
{
    static_assert(sizeof(T) % sizeof(Scalar) == 0);
    auto* keep = new std::shared_ptr<Owner>(owner);
    py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<Owner>*>(p); });
    return py::array_t<Scalar>(shape, reinterpret_cast<const Scalar*>(data.data()), base);
}

py::tuple tuple3(const glm::vec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple tuple3(const glm::dvec3& v) { return py::make_tuple(v.x, v.y, v.z); }

glm::dvec3 vec3Of(const py::handle& h, const char* what)
{
    const auto v = h.cast<std::vector<double>>();
    if (v.size() != 3) throw Error(std::string(what) + ": expected 3 numbers, got " + std::to_string(v.size()));
    for (double x : v)
        if (!std::isfinite(x)) throw Error(std::string(what) + ": expected finite numbers");
    return {v[0], v[1], v[2]};
}

// ---- scenes ----

// The scene as a file would hold it, read back: every check of the scene file (ranges, species names, paths) with
// messages naming the key. Throws Error.
void checkScene(const Scene& scene)
{
    (void)parseScene(sceneToJson(scene, std::filesystem::current_path().string()), std::string(), "scene");
}

// The scene a job runs: checked, its Preetham sky built for its sun, its terrain loaded.
Scene jobScene(const Scene& scene)
{
    checkScene(scene);
    Scene s = scene;
    if (s.skyModel.kind == sky::SkyKind::Preetham) s.skyModel.built.reset();
    if (!s.skyModel.built) loadSceneSky(s);
    loadSceneTerrain(s);
    return s;
}

py::object jsonModule() { return py::module_::import("json"); }

size_t speciesIndex(const Scene& scene, const py::handle& species)
{
    if (py::isinstance<py::str>(species)) {
        const std::string name = species.cast<std::string>();
        for (size_t i = 0; i < scene.species.size(); ++i)
            if (scene.species[i].name == name) return i;
        throw py::key_error("no species named '" + name + "' in the scene");
    }
    const long long i = species.cast<long long>();
    if (i < 0 || size_t(i) >= scene.species.size())
        throw py::index_error("species " + std::to_string(i) + ": the scene has " + std::to_string(scene.species.size()));
    return size_t(i);
}

// Instances from arrays: positions (N, 3); rotations (N, 3) degrees or (N,) about +Y or None; scales (N,) or None.
std::vector<InstanceDesc> instancesOf(const Scene& scene, const py::handle& species, const py::array_t<double>& positions,
                                      const py::object& rotations, const py::object& scales, bool onTerrain)
{
    const size_t sp = speciesIndex(scene, species);
    const auto p = positions.unchecked<2>();
    if (p.shape(1) != 3) throw Error("positions: expected an (N, 3) array");
    const size_t n = size_t(p.shape(0));
    std::vector<InstanceDesc> out(n);
    for (size_t i = 0; i < n; ++i) {
        out[i].species = uint32_t(sp);
        out[i].position = {p(i, 0), p(i, 1), p(i, 2)};
        out[i].onTerrain = onTerrain;
    }
    if (!rotations.is_none()) {
        const auto r = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(rotations);
        if (!r) throw Error("rotations: expected an array");
        if (r.ndim() == 1 && size_t(r.shape(0)) == n) {
            for (size_t i = 0; i < n; ++i) out[i].rotationDeg = {0.0f, float(r.at(i)), 0.0f};
        } else if (r.ndim() == 2 && size_t(r.shape(0)) == n && r.shape(1) == 3) {
            for (size_t i = 0; i < n; ++i) out[i].rotationDeg = {float(r.at(i, 0)), float(r.at(i, 1)), float(r.at(i, 2))};
        } else {
            throw Error("rotations: expected (N,) degrees about +Y or (N, 3) degrees, N = " + std::to_string(n));
        }
    }
    if (!scales.is_none()) {
        const auto s = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(scales);
        if (!s || s.ndim() != 1 || size_t(s.shape(0)) != n) throw Error("scales: expected (N,), N = " + std::to_string(n));
        for (size_t i = 0; i < n; ++i) out[i].scale = float(s.at(i));
    }
    for (size_t i = 0; i < n; ++i) {
        const InstanceDesc& d = out[i];
        bool finite = std::isfinite(d.scale);
        for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(d.position[c]) && std::isfinite(d.rotationDeg[c]);
        if (!finite) throw Error("instance " + std::to_string(i) + ": non-finite position, rotation or scale");
        if (!(d.scale > 0.0f)) throw Error("instance " + std::to_string(i) + ": scale must be > 0, got " + std::to_string(d.scale));
    }
    return out;
}

py::dict instanceArrays(const Scene& scene)
{
    const size_t n = scene.instances.size();
    const py::ssize_t rows = py::ssize_t(n);
    py::array_t<uint32_t> species{std::vector<py::ssize_t>{rows}};
    py::array_t<double> position{std::vector<py::ssize_t>{rows, 3}};
    py::array_t<float> rotation{std::vector<py::ssize_t>{rows, 3}};
    py::array_t<float> scale{std::vector<py::ssize_t>{rows}};
    py::array_t<bool> onTerrain{std::vector<py::ssize_t>{rows}};
    auto sp = species.mutable_unchecked<1>();
    auto po = position.mutable_unchecked<2>();
    auto ro = rotation.mutable_unchecked<2>();
    auto sc = scale.mutable_unchecked<1>();
    auto te = onTerrain.mutable_unchecked<1>();
    for (size_t i = 0; i < n; ++i) {
        const InstanceDesc& d = scene.instances[i];
        sp(i) = d.group == kNoGroup ? d.species : kNoGroup;
        for (int c = 0; c < 3; ++c) {
            po(i, c) = d.position[c];
            ro(i, c) = d.rotationDeg[c];
        }
        sc(i) = d.scale;
        te(i) = d.onTerrain;
    }
    return py::dict("species"_a = species, "position"_a = position, "rotation"_a = rotation, "scale"_a = scale,
                    "on_terrain"_a = onTerrain);
}

// ---- jobs ----

std::unique_ptr<GridCache> cacheOf(const py::object& cache)
{
    if (cache.is_none()) return std::make_unique<GridCache>();
    if (py::isinstance<py::bool_>(cache)) return cache.cast<bool>() ? std::make_unique<GridCache>() : nullptr;
    return std::make_unique<GridCache>(py::str(cache).cast<std::string>());
}

std::unique_ptr<Backend> backendOf(const std::string& name)
{
    py::object warn = py::module_::import("warnings").attr("warn");
    return selectBackend(name, [&](const std::string& note) { warn(note); });
}

void warnLog(const JobLog& log)
{
    if (log.warnings.empty()) return;
    py::object warn = py::module_::import("warnings").attr("warn");
    for (const std::string& w : log.warnings) warn(w);
}

struct Mesh {
    TriangleMesh mesh;
};

py::object meshObject(TriangleMesh mesh)
{
    return py::cast(std::make_shared<Mesh>(Mesh{std::move(mesh)}));
}

struct Grids {
    SpeciesGrids grids;
    std::string species;
};

struct Render {
    Film film;
    MatteFilm mattes;
    Scene scene;
    RenderTimings timings;
    std::vector<glm::vec3> linear;
    float ambient = 0.0f;
};

py::dict geometryDict(const GridGeometry& g)
{
    return py::dict("dims"_a = py::make_tuple(g.dims.x, g.dims.y, g.dims.z), "origin"_a = tuple3(g.origin), "spacing"_a = g.spacing);
}

GrowSpec growSpecOf(const std::string& species, uint64_t seed, uint64_t triangles, float height)
{
    GrowSpec g;
    g.species = species;
    g.seed = seed;
    g.triangles = triangles;
    g.height = height;
    return g;
}

} // namespace
} // namespace sylva::python

PYBIND11_MODULE(sylva, m)
{
    using namespace sylva;
    using namespace sylva::python;
    m.doc() = "Sylva: forests and landscapes with lattice-Boltzmann lighting (docs/PYTHON.md)";
    m.attr("__version__") = SYLVA_VERSION;
    findImageModule();
    static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
    static py::exception<Cancelled> cancelled(m, "Cancelled", PyExc_Exception);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Cancelled& e) {
            cancelled(e.what());
        } catch (const Error& e) {
            error(e.what());
        }
    });

    py::class_<CancelToken, std::shared_ptr<CancelToken>>(m, "CancelToken",
        "Stops a job from another thread: pass it as cancel=, call cancel(); the job raises sylva.Cancelled.")
        .def(py::init<>())
        .def("cancel", [](CancelToken& t) { t.cancelled = true; })
        .def_property_readonly("cancelled", [](const CancelToken& t) { return t.cancelled.load(); });

    // ---- scene parts, edited in place through the scene ----
    py::class_<RenderSettings>(m, "RenderSettings", "The scene's render block (docs/SCENE.md)")
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("spp", &RenderSettings::spp)
        .def_readwrite("exposure_key", &RenderSettings::exposureKey)
        .def_readwrite("view", &RenderSettings::view)
        .def_readwrite("display", &RenderSettings::display)
        .def_readwrite("max_bounces", &RenderSettings::maxBounces)
        .def_readwrite("bounce_samples", &RenderSettings::bounceSamples)
        .def_readwrite("shadows", &RenderSettings::shadows)
        .def_property("mode", [](const RenderSettings& r) { return std::string(renderModeName(r.mode)); },
                      [](RenderSettings& r, const std::string& v) {
                          if (!parseRenderMode(v, &r.mode)) throw Error("render.mode: expected full, local, ambient or lb, got '" + v + "'");
                      })
        .def_property("integrator", [](const RenderSettings& r) { return std::string(integratorName(r.integrator)); },
                      [](RenderSettings& r, const std::string& v) {
                          if (!parseIntegrator(v, &r.integrator)) throw Error("render.integrator: expected lb or path, got '" + v + "'");
                      })
        .def_property("leaf_tint", [](const RenderSettings& r) { return tuple3(r.leafTint); },
                      [](RenderSettings& r, const py::object& v) { r.leafTint = glm::vec3(vec3Of(v, "render.leaf_tint")); });

    py::class_<SunDesc>(m, "Sun", "The scene's sun: direction toward it (+Y up), intensity, temperature in kelvin")
        .def_property("direction", [](const SunDesc& s) { return tuple3(s.direction); },
                      [](SunDesc& s, const py::object& v) {
                          const glm::vec3 d(vec3Of(v, "sun.direction"));
                          if (!(glm::length(d) > 0.0f)) throw Error("sun.direction: must not be zero");
                          s.direction = d;
                          s.place.reset();
                      })
        .def("set_angles", [](SunDesc& s, double elevation, double azimuth) {
                 s.direction = sunDirection(elevation, azimuth);
                 s.place.reset();
             }, "elevation"_a, "azimuth"_a, "Degrees above the horizon and from +Z toward +X")
        .def_readwrite("intensity", &SunDesc::intensity)
        .def_readwrite("temperature", &SunDesc::temperature);

    py::class_<CameraDesc>(m, "Camera", "The scene's camera: position and target in metres, vertical field of view in degrees")
        .def_property("position", [](const CameraDesc& c) { return tuple3(c.position); },
                      [](CameraDesc& c, const py::object& v) { c.position = vec3Of(v, "camera.position"); })
        .def_property("target", [](const CameraDesc& c) { return tuple3(c.target); },
                      [](CameraDesc& c, const py::object& v) { c.target = vec3Of(v, "camera.target"); })
        .def_readwrite("fov", &CameraDesc::fovY);

    py::class_<GroundDesc>(m, "Ground", "The ground plane: enabled, height (metres), colour (linear RGB albedo)")
        .def_readwrite("enabled", &GroundDesc::enabled)
        .def_readwrite("height", &GroundDesc::height)
        .def_property("color", [](const GroundDesc& g) { return tuple3(g.color); },
                      [](GroundDesc& g, const py::object& v) { g.color = glm::vec3(vec3Of(v, "ground.color")); });

    // ---- the scene ----
    py::class_<Scene>(m, "Scene", "A scene (docs/SCENE.md): Scene() is the studio's new scene, Scene.load(path) a file")
        .def(py::init([] { return newSceneDefaults(); }))
        .def_static("load", [](const std::string& path) { return readSceneFile(path); }, "path"_a, "Reads a .sylva.json scene file")
        .def_static("default", [] { return defaultScene(); }, "The bundled default forest")
        .def_static("from_json", [](const std::string& text, const std::string& baseDir) { return parseScene(text, baseDir, "scene"); },
                    "text"_a, "base_dir"_a = std::string(), "A scene from scene-file JSON text (mesh paths relative to base_dir)")
        .def_static("from_dict", [](const py::object& d, const std::string& baseDir) {
                        return parseScene(jsonModule().attr("dumps")(d).cast<std::string>(), baseDir, "scene");
                    }, "data"_a, "base_dir"_a = std::string(), "A scene from the scene file's structure as Python dicts and lists")
        .def("to_json", [](const Scene& s, const std::string& baseDir) {
                 return sceneToJson(s, baseDir.empty() ? std::filesystem::current_path().string() : baseDir);
             }, "base_dir"_a = std::string(), "The scene-file JSON text (mesh paths relative to base_dir, default the current folder)")
        .def("to_dict", [](const Scene& s, const std::string& baseDir) {
                 return jsonModule().attr("loads")(sceneToJson(s, baseDir.empty() ? std::filesystem::current_path().string() : baseDir));
             }, "base_dir"_a = std::string(), "The scene file's structure as Python dicts and lists; edit it and read it back with from_dict")
        .def("save", [](const Scene& s, const std::string& path) {
                 checkScene(s);
                 writeSceneFile(s, path);
             }, "path"_a, "Writes the scene file (atomically); refuses a scene the file reader would refuse")
        .def("check", [](const Scene& s) { checkScene(s); }, "Raises sylva.Error naming the key of the first value a scene file refuses")
        .def("copy", [](const Scene& s) { return s; })
        .def("describe", [](const Scene& s) { return describeScene(s); }, "What `sylva info` says of the scene")
        .def("apply_quality", [](Scene& s, const std::string& name) {
                 const QualityPreset* q = findQualityPreset(name);
                 if (!q) throw Error("quality: expected preview, final or reference, got '" + name + "'");
                 applyQuality(s, *q);
             }, "name"_a, "Sets every knob of a quality preset (preview, final, reference; docs/ACCURACY.md)")
        .def_property_readonly("render", [](Scene& s) -> RenderSettings& { return s.render; }, py::return_value_policy::reference_internal)
        .def_property_readonly("sun", [](Scene& s) -> SunDesc& { return s.sun; }, py::return_value_policy::reference_internal)
        .def_property_readonly("camera", [](Scene& s) -> CameraDesc& { return s.camera; }, py::return_value_policy::reference_internal)
        .def_property_readonly("ground", [](Scene& s) -> GroundDesc& { return s.ground; }, py::return_value_policy::reference_internal)
        .def_property("sky_color", [](const Scene& s) { return tuple3(s.sky); },
                      [](Scene& s, const py::object& v) { s.sky = glm::vec3(vec3Of(v, "sky.color")); })
        .def_property_readonly("species", [](const Scene& s) {
                                   std::vector<std::string> names;
                                   for (const SpeciesDesc& sp : s.species) names.push_back(sp.name);
                                   return names;
                               }, "The species' names, in order (instances refer to them by index)")
        .def("add_species", [](Scene& s, const py::object& mesh, const py::object& grow, const std::string& name, int grid) {
                 if (mesh.is_none() == grow.is_none()) throw Error("add_species: give either mesh= (a file) or grow= (a grower species)");
                 SpeciesDesc sp = defaultSpecies();
                 std::string wish = name;
                 if (!mesh.is_none()) {
                     const std::filesystem::path p = std::filesystem::absolute(py::str(mesh).cast<std::string>()).lexically_normal();
                     if (!std::filesystem::exists(p)) throw Error(p.string() + ": no such mesh file");
                     sp.meshPath = p.string();
                     if (wish.empty()) wish = p.stem().string();
                 } else if (py::isinstance<py::str>(grow)) {
                     sp.grow = growSpecOf(grow.cast<std::string>(), 1, 100000, 0.0f);
                 } else {
                     const py::dict g = grow.cast<py::dict>();
                     sp.grow = growSpecOf(g.contains("species") ? g["species"].cast<std::string>() : std::string("broadleaf"),
                                          g.contains("seed") ? g["seed"].cast<uint64_t>() : 1,
                                          g.contains("triangles") ? g["triangles"].cast<uint64_t>() : 100000,
                                          g.contains("height") ? g["height"].cast<float>() : 0.0f);
                 }
                 if (sp.grow && wish.empty()) wish = sp.grow->species + " " + std::to_string(sp.grow->seed);
                 sp.name = uniqueSpeciesName(s, wish);
                 sp.grid = grid;
                 s.species.push_back(sp);
                 try {
                     checkScene(s);
                 } catch (...) {
                     s.species.pop_back();
                     throw;
                 }
                 return s.species.size() - 1;
             }, "mesh"_a = py::none(), "grow"_a = py::none(), "name"_a = std::string(), "grid"_a = 64,
             "Adds a species from a mesh file or grown (grow='birch' or a dict of species, seed, triangles, height); returns its index")
        .def_property_readonly("instance_count", [](const Scene& s) { return s.instances.size(); })
        .def("instances", &instanceArrays,
             "The instances as arrays (copies): species (N,), position (N, 3) metres, rotation (N, 3) degrees, scale (N,), on_terrain (N,)")
        .def("add_instances", [](Scene& s, const py::handle& species, const py::array_t<double, py::array::c_style | py::array::forcecast>& positions,
                                 const py::object& rotations, const py::object& scales, bool onTerrain) {
                 const std::vector<InstanceDesc> add = instancesOf(s, species, positions, rotations, scales, onTerrain);
                 s.instances.insert(s.instances.end(), add.begin(), add.end());
                 return add.size();
             }, "species"_a, "positions"_a, "rotations"_a = py::none(), "scales"_a = py::none(), "on_terrain"_a = false,
             "Places instances of a species (index or name): positions (N, 3); rotations (N,) degrees about +Y or (N, 3); scales (N,)")
        .def("clear_instances", [](Scene& s) { s.instances.clear(); });

    // ---- meshes, grids, renders ----
    py::class_<Mesh, std::shared_ptr<Mesh>>(m, "Mesh", "A triangle mesh in metres; arrays share its memory")
        .def_property_readonly("positions", [](const std::shared_ptr<Mesh>& h) {
            return arrayOver<float>(h, h->mesh.positions, {py::ssize_t(h->mesh.positions.size()), 3});
        })
        .def_property_readonly("normals", [](const std::shared_ptr<Mesh>& h) {
            return arrayOver<float>(h, h->mesh.normals, {py::ssize_t(h->mesh.normals.size()), 3});
        })
        .def_property_readonly("uvs", [](const std::shared_ptr<Mesh>& h) {
            return arrayOver<float>(h, h->mesh.uvs, {py::ssize_t(h->mesh.uvs.size()), 2});
        })
        .def_property_readonly("triangles", [](const std::shared_ptr<Mesh>& h) {
            return arrayOver<uint32_t>(h, h->mesh.triangles, {py::ssize_t(h->mesh.triangles.size()), 3});
        })
        .def_property_readonly("triangle_material", [](const std::shared_ptr<Mesh>& h) {
            return arrayOver<uint32_t>(h, h->mesh.triangleMaterial, {py::ssize_t(h->mesh.triangleMaterial.size())});
        })
        .def_property_readonly("materials", [](const Mesh& h) {
            py::list out;
            for (const Material& mat : h.mesh.materials)
                out.append(py::dict("name"_a = mat.name, "leaf"_a = mat.isLeaf, "diffuse"_a = tuple3(mat.diffuse),
                                    "diffuse_texture"_a = mat.diffuseTexture));
            return out;
        })
        .def_property_readonly("triangle_count", [](const Mesh& h) { return h.mesh.triangleCount(); });

    py::class_<Grids, std::shared_ptr<Grids>>(m, "Grids", "A species' density and LB lighting grids (species frame); arrays share their memory")
        .def_property_readonly("species", [](const Grids& g) { return g.species; })
        .def_property_readonly("density", [](const std::shared_ptr<Grids>& h) {
            const glm::ivec3 d = h->grids.density.geometry.dims;
            return arrayOver<float>(h, h->grids.density.density, {d.x, d.y, d.z});
        }, "Medium density per node, shape (X, Y, Z)")
        .def_property_readonly("wood", [](const std::shared_ptr<Grids>& h) {
            const glm::ivec3 d = h->grids.density.geometry.dims;
            return arrayOver<float>(h, h->grids.density.woodFraction, {d.x, d.y, d.z});
        }, "Wood fraction per node, shape (X, Y, Z)")
        .def_property_readonly("lighting", [](const std::shared_ptr<Grids>& h) {
            const glm::ivec3 d = h->grids.lighting.geometry.dims;
            return arrayOver<float>(h, h->grids.lighting.rgb, {d.x, d.y, d.z, 3});
        }, "Photon density per node and channel, shape (X, Y, Z, 3)")
        .def_property_readonly("lighting_norm", [](const Grids& g) { return tuple3(g.grids.lightingNorm); },
                               "Photon density of open space per channel (the renderer divides the lighting by it)")
        .def_property_readonly("geometry", [](const Grids& g) { return geometryDict(g.grids.density.geometry); },
                               "dims, origin (metres, node 0) and spacing (metres)");

    py::class_<Render, std::shared_ptr<Render>>(m, "Render", "A rendered frame")
        .def_property_readonly("width", [](const Render& r) { return r.film.width; })
        .def_property_readonly("height", [](const Render& r) { return r.film.height; })
        .def_property_readonly("linear", [](const std::shared_ptr<Render>& h) {
            return arrayOver<float>(h, h->linear, {h->film.height, h->film.width, 3});
        }, "The scene-linear Rec.709 picture of the scene's mode, shape (height, width, 3), row 0 at the top")
        .def_property_readonly("timings", [](const Render& r) {
            return py::dict("assets"_a = r.timings.assets, "build"_a = r.timings.build, "trace"_a = r.timings.trace);
        }, "Seconds spent on assets (meshes, LB grids), acceleration structures and tracing")
        .def("picture", [](const Render& r) {
            ImageRgba img = toneMapped(r.linear, r.film.width, r.film.height, r.scene.render.exposureKey, displayTransformOf(r.scene.render));
            auto owner = std::make_shared<ImageRgba>(std::move(img));
            return arrayOver<float>(owner, owner->pixels, {owner->height, owner->width, 4});
        }, "The display picture through the scene's view (render.view): (height, width, 4) in [0, 1]")
        .def("passes", [](const Render& r) {
            const RenderPasses p = renderPasses(r.film, r.scene.render.mode, composeSky(r.scene));
            py::dict out;
            const py::ssize_t w = p.width, hgt = p.height;
            auto rgb = [&](const std::vector<glm::vec3>& v) {
                return py::array_t<float>({hgt, w, py::ssize_t(3)}, reinterpret_cast<const float*>(v.data()));
            };
            out["combined"] = rgb(p.combined);
            out["diffuse_direct"] = rgb(p.diffDir);
            out["diffuse_indirect"] = rgb(p.diffInd);
            out["diffuse_color"] = rgb(p.diffCol);
            out["environment"] = rgb(p.env);
            out["normal"] = rgb(p.normal);
            out["depth"] = py::array_t<float>({hgt, w}, p.depth.data());
            out["alpha"] = py::array_t<float>({hgt, w}, p.alpha.data());
            return out;
        }, "The render passes (the layers of `sylva render --passes`) as arrays (copies)")
        .def("save", [](const Render& r, const std::string& path, bool passes) {
                 writeRenderFilm(path, r.film, r.scene, passes, r.mattes.width > 0 ? &r.mattes : nullptr);
             }, "path"_a, "passes"_a = false,
             "Writes .png/.tif (through the scene's view) or .exr (linear); passes=True: the multi-layer EXR with Cryptomatte "
             "(render with mattes=True)");

    // ---- jobs ----
    m.def("grow", [](const std::string& species, uint64_t seed, size_t triangles, float height, const py::object& obj,
                     const py::object& progress, const std::shared_ptr<CancelToken>& cancel) {
              JobContext job(progress, cancel);
              GrowOptions o;
              o.species = speciesFromName(species);
              o.seed = seed;
              o.targetTriangles = triangles;
              o.height = height;
              const std::string objPath = obj.is_none() ? std::string() : py::str(obj).cast<std::string>();
              TriangleMesh mesh = job.run([&] {
                  GrownTree tree = growTree(o, &job.progress());
                  if (!objPath.empty()) writeObj(objPath, tree);
                  return std::move(tree.mesh);
              });
              return meshObject(std::move(mesh));
          },
          "species"_a = "broadleaf", "seed"_a = 1, "triangles"_a = 100000, "height"_a = 0.0f, "obj"_a = py::none(),
          "progress"_a = py::none(), "cancel"_a = nullptr,
          "Grows a tree (broadleaf, birch, conifer, shrub); obj=PATH also writes it with its material and textures");
    m.def("import_mesh", [](const std::string& path) {
              ImportReport report;
              TriangleMesh mesh;
              {
                  py::gil_scoped_release release;
                  mesh = importMesh(path, ImportOptions{}, &report);
              }
              py::object warn = py::module_::import("warnings").attr("warn");
              for (const std::string& w : report.warnings) warn(w);
              return meshObject(std::move(mesh));
          },
          "path"_a, "Reads a plant mesh (OBJ, FBX, glTF, PLY, ...) as `sylva import` does: leaves and wood told apart, cleaned");
    m.def("light", [](const Scene& scene, const py::object& species, const py::object& cache, const std::string& backend,
                      const py::object& progress, const std::shared_ptr<CancelToken>& cancel) {
              const Scene s = jobScene(scene);
              const size_t index = speciesIndex(s, species);
              auto c = cacheOf(cache);
              auto b = backendOf(backend);
              JobContext job(progress, cancel);
              JobLog log;
              auto out = std::make_shared<Grids>();
              out->species = s.species[index].name;
              out->grids = job.run([&] { return loadSpeciesGrids(s, index, c.get(), &job.progress(), &log, nullptr, b.get()); });
              warnLog(log);
              return out;
          },
          "scene"_a, "species"_a = 0, "cache"_a = py::none(), "backend"_a = "auto", "progress"_a = py::none(), "cancel"_a = nullptr,
          "A species' density and LB lighting grids for the scene's sun and sky, through the grid cache "
          "(cache=None: the user's cache, False: none, or a folder)");
    m.def("render", [](const Scene& scene, const py::object& cache, const std::string& backend, bool mattes, const py::object& progress,
                       const std::shared_ptr<CancelToken>& cancel) {
              auto out = std::make_shared<Render>();
              out->scene = jobScene(scene);
              if (!frameFitsMemory(out->scene.render))
                  throw Error("render: the " + std::to_string(out->scene.render.width) + "x" + std::to_string(out->scene.render.height) +
                              " frame does not fit in the available memory; render it with `sylva render`, which traces it in bands");
              auto c = cacheOf(cache);
              auto b = backendOf(backend);
              JobContext job(progress, cancel);
              JobLog log;
              RenderOutput result = job.run([&] { return renderScene(out->scene, c.get(), &job.progress(), &log, b.get(), {}, mattes); });
              warnLog(log);
              out->film = std::move(result.film);
              out->mattes = std::move(result.mattes);
              out->timings = result.timings;
              out->linear = composeMode(out->film, out->scene.render.mode, composeSky(out->scene), &out->ambient);
              return out;
          },
          "scene"_a, "cache"_a = py::none(), "backend"_a = "auto", "mattes"_a = false, "progress"_a = py::none(), "cancel"_a = nullptr,
          "Renders the scene as `sylva render` does (same picture); mattes=True keeps the Cryptomatte samples for save(passes=True)");
    m.def("export_gltf", [](const Scene& scene, const std::string& path, const py::object& region, const py::object& species, bool force,
                            const py::object& progress, const std::shared_ptr<CancelToken>& cancel) {
              const Scene s = jobScene(scene);
              GltfExportOptions o;
              if (!region.is_none()) {
                  const auto r = region.cast<std::vector<double>>();
                  if (r.size() != 4) throw Error("region: expected (x0, z0, x1, z1)");
                  o.region = parseGltfRegion(std::to_string(r[0]) + "," + std::to_string(r[1]) + "," + std::to_string(r[2]) + "," +
                                             std::to_string(r[3]));
              }
              if (!species.is_none())
                  for (const py::handle h : species) o.species.push_back(speciesIndex(s, h));
              o.force = force;
              JobContext job(progress, cancel);
              const GltfPlan plan = job.run([&] {
                  const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false, &job.progress());
                  return exportGltf(s, assets, path, o, &job.progress());
              });
              return py::dict("instances"_a = plan.instances, "per_species"_a = plan.perSpecies, "bytes"_a = plan.estimatedBytes,
                              "summary"_a = plan.summary());
          },
          "scene"_a, "path"_a, "region"_a = py::none(), "species"_a = py::none(), "force"_a = false, "progress"_a = py::none(),
          "cancel"_a = nullptr,
          "Writes the scene as an instanced glTF (.glb) as `sylva export scene` does; returns the counts written");
    m.def("export_grids", [](const Scene& scene, const py::object& species, const std::string& folder, const std::string& format,
                             const py::object& cache, const std::string& backend, const py::object& progress,
                             const std::shared_ptr<CancelToken>& cancel) {
              const Scene s = jobScene(scene);
              const size_t index = speciesIndex(s, species);
              GridFileFormat f = GridFileFormat::Npy;
              if (format == "vdb") f = GridFileFormat::Vdb;
              else if (format != "npy") throw Error("format: expected npy or vdb, got '" + format + "'");
              auto c = cacheOf(cache);
              auto b = backendOf(backend);
              JobContext job(progress, cancel);
              JobLog log;
              const GridExportFiles files =
                  job.run([&] { return exportSpeciesGrids(s, index, folder, c.get(), b.get(), &job.progress(), &log, nullptr, f); });
              warnLog(log);
              return py::dict("density"_a = files.density, "lighting"_a = files.lighting);
          },
          "scene"_a, "species"_a, "folder"_a, "format"_a = "npy", "cache"_a = py::none(), "backend"_a = "auto", "progress"_a = py::none(),
          "cancel"_a = nullptr, "Writes a species' grids as the studio's grid export does (.npy with sidecars, or one .vdb)");
    m.def("quality_presets", [] {
        std::vector<std::string> names;
        for (const QualityPreset& q : qualityPresets()) names.push_back(q.name);
        return names;
    });
    m.def("grower_species", [] { return speciesNames(); }, "The species the grower knows");
    m.def("sun_direction", [](double elevation, double azimuth) { return tuple3(sunDirection(elevation, azimuth)); }, "elevation"_a,
          "azimuth"_a, "Direction toward the sun from degrees above the horizon and from +Z toward +X");
}
