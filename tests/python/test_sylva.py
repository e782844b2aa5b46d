"""The Python module against independent oracles: the `sylva` program on the same scene file (pictures, grids),
the scene file format, closed forms, and the glTF file's own structure. Run by ctest (tst_python) with PYTHONPATH on
the built module and SYLVA_CLI naming the built program."""

import gc
import json
import os
import re
import struct
import subprocess
import tempfile
import threading
import unittest

import numpy as np

import sylva

CLI = os.environ.get("SYLVA_CLI", "sylva")
SOURCE = os.environ.get("SYLVA_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
RESOURCES = os.path.join(SOURCE, "resources")


def exr_without_dates(data):
    """An OpenEXR file's bytes less its header's time stamp attributes (capDate, DateTime): what two writes of the
    same pixels at different times share. The header is name\\0 type\\0 size value ..., ending in an empty name."""
    assert data[:4] == b"\x76\x2f\x31\x01", "not an OpenEXR file"
    out, pos = bytearray(data[:8]), 8
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        end = type_end + 5 + size
        if data[pos:name_end] not in (b"capDate", b"DateTime"):
            out += data[pos:end]
        pos = end
    return bytes(out + data[pos:])


def small_scene():
    """Two grown shrubs on the ground under the constant sky, 64x32 pixels, looking along +Z at eye level."""
    scene = sylva.Scene()
    scene.add_species(grow={"species": "shrub", "triangles": 2000, "seed": 3}, grid=24)
    scene.add_instances(0, np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 1.0]]), rotations=np.array([0.0, 60.0]))
    scene.camera.position = (0.5, 1.0, -6.0)
    scene.camera.target = (0.5, 1.0, 0.0)
    scene.render.width, scene.render.height, scene.render.spp = 64, 32, 1
    return scene


class Files(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory()
        self.tmp = self._tmp.name
        self.cache = os.path.join(self.tmp, "cache")

    def tearDown(self):
        self._tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp, name)

    def run_cli(self, *args):
        r = subprocess.run([CLI, *args, "--quiet"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        return r.stdout


class SceneFiles(Files):
    def test_round_trip_through_dicts_and_files(self):
        scene = sylva.Scene.load(os.path.join(RESOURCES, "default_forest.sylva.json"))
        data = scene.to_dict(base_dir=RESOURCES)
        again = sylva.Scene.from_dict(data, base_dir=RESOURCES)
        self.assertEqual(again.to_dict(base_dir=RESOURCES), data)
        self.assertEqual(scene.instance_count, len(data["instances"]))
        out = self.path("copy.sylva.json")
        scene.save(out)
        with open(out) as f:
            self.assertEqual(json.load(f), scene.to_dict(base_dir=self.tmp))
        self.assertEqual(sylva.Scene.load(out).to_dict(base_dir=self.tmp), scene.to_dict(base_dir=self.tmp))

    def test_typed_edits_reach_the_file(self):
        scene = sylva.Scene()
        scene.sun.set_angles(30.0, 90.0)
        # Closed form: elevation 30 degrees, azimuth 90 (toward +X).
        np.testing.assert_allclose(scene.sun.direction, (np.cos(np.radians(30)), 0.5, 0.0), atol=1e-6)
        np.testing.assert_allclose(sylva.sun_direction(30.0, 90.0), scene.sun.direction, atol=1e-7)
        scene.render.width = 320
        scene.render.mode = "local"
        scene.ground.color = (0.3, 0.2, 0.1)
        scene.camera.fov = 30.0
        data = scene.to_dict()
        self.assertEqual(data["render"]["width"], 320)
        self.assertEqual(data["render"]["mode"], "local")
        np.testing.assert_allclose(data["ground"]["color"], (0.3, 0.2, 0.1), atol=1e-7)
        self.assertAlmostEqual(data["camera"]["fov"], 30.0, places=5)
        np.testing.assert_allclose(data["sun"]["direction"], scene.sun.direction, atol=1e-7)

    def test_bad_values_are_refused_naming_the_key(self):
        scene = sylva.Scene()
        scene.render.width = -5
        with self.assertRaisesRegex(sylva.Error, r"render\.width"):
            scene.check()
        out = self.path("bad.sylva.json")
        with self.assertRaises(sylva.Error):
            scene.save(out)
        self.assertFalse(os.path.exists(out), "a refused scene leaves no file")
        with self.assertRaisesRegex(sylva.Error, r"render\.mode"):
            scene.render.mode = "sharp"
        data = sylva.Scene().to_dict()
        data["sun"]["colour"] = 1
        with self.assertRaisesRegex(sylva.Error, r"sun\.colour"):
            sylva.Scene.from_dict(data)
        with self.assertRaisesRegex(sylva.Error, r"scale must be > 0"):
            small_scene().add_instances(0, np.zeros((1, 3)), scales=np.array([0.0]))
        with self.assertRaises(KeyError):
            small_scene().add_instances("oak", np.zeros((1, 3)))
        with self.assertRaisesRegex(sylva.Error, r"no such mesh file"):
            sylva.Scene().add_species(mesh=self.path("missing.obj"))

    def test_species_names_stay_unique(self):
        scene = sylva.Scene()
        self.assertEqual(scene.add_species(grow="birch"), 0)
        self.assertEqual(scene.add_species(grow="birch"), 1)
        self.assertEqual(scene.species, ["birch 1", "birch 1 (2)"])


class Jobs(Files):
    def test_render_equals_the_program(self):
        scene_file = self.path("two.sylva.json")
        small_scene().save(scene_file)
        self.run_cli("render", scene_file, "--cache", self.cache, "-o", self.path("cli.exr"))
        self.run_cli("render", scene_file, "--cache", self.cache, "-o", self.path("cli.png"))
        result = sylva.render(sylva.Scene.load(scene_file), cache=self.cache)
        result.save(self.path("py.exr"))
        result.save(self.path("py.png"))
        for ext in ("exr", "png"):
            with open(self.path("cli." + ext), "rb") as a, open(self.path("py." + ext), "rb") as b:
                cli, py = a.read(), b.read()
            if ext == "exr":
                cli, py = exr_without_dates(cli), exr_without_dates(py)
            self.assertEqual(cli, py, ext + ": the module's picture differs from sylva render's")
        self.assertEqual(result.linear.shape, (32, 64, 3))
        self.assertEqual(result.picture().shape, (32, 64, 4))

    def test_passes_and_mattes_equal_the_program(self):
        scene_file = self.path("two.sylva.json")
        small_scene().save(scene_file)
        self.run_cli("render", scene_file, "--cache", self.cache, "--passes", "-o", self.path("cli.exr"))
        result = sylva.render(sylva.Scene.load(scene_file), cache=self.cache, mattes=True)
        result.save(self.path("py.exr"), passes=True)
        with open(self.path("cli.exr"), "rb") as a, open(self.path("py.exr"), "rb") as b:
            cli = exr_without_dates(a.read())
            self.assertEqual(cli, exr_without_dates(b.read()), "the module's passes differ from sylva render --passes'")
        self.assertIn(b"CryptoAsset", cli)
        passes = result.passes()
        np.testing.assert_array_equal(passes["combined"], result.linear)
        self.assertTrue(np.all((passes["alpha"] >= 0.0) & (passes["alpha"] <= 1.0)))

    def test_sky_pixels_are_the_sky(self):
        # Local mode, constant sky: a pixel that sees only sky is the sky's radiance (composeMode's closed form).
        scene = small_scene()
        scene.render.mode = "local"
        scene.sky_color = (0.25, 0.5, 1.0)
        scene.camera.position = (0.5, 0.3, -6.0)
        scene.camera.target = (0.5, 3.0, 0.0)   # looking up: the top row sees sky
        linear = sylva.render(scene, cache=False).linear
        np.testing.assert_allclose(linear[0, 0], (0.25, 0.5, 1.0), rtol=1e-6)
        self.assertFalse(linear.flags.owndata, "the film is shared, not copied")

    def test_arrays_keep_their_owner_alive(self):
        linear = sylva.render(small_scene(), cache=self.cache).linear
        total = float(linear.sum())
        gc.collect()
        garbage = [np.ones(linear.size, np.float32) for _ in range(8)]
        self.assertEqual(float(linear.sum()), total)
        del garbage

    def test_scene_without_plants(self):
        scene = sylva.Scene()
        scene.render.width, scene.render.height = 32, 16
        linear = sylva.render(scene, cache=False).linear
        self.assertEqual(linear.shape, (16, 32, 3))
        self.assertTrue(np.all(np.isfinite(linear)) and linear.max() > 0.0)

    def test_grids_equal_the_programs_export(self):
        scene_file = self.path("two.sylva.json")
        small_scene().save(scene_file)
        self.run_cli("export", scene_file, "--format", "npy", "--out", self.path("cli"), "--no-cache")
        grids = sylva.light(sylva.Scene.load(scene_file), species="shrub 3", cache=False)
        base = os.path.join(self.path("cli"), "shrub_3")
        density = np.load(base + ".density.npy")
        lighting = np.load(base + ".lighting.npy")
        self.assertEqual(grids.density.shape, tuple(grids.geometry["dims"]))
        np.testing.assert_array_equal(grids.density, density.reshape(grids.density.shape))
        np.testing.assert_array_equal(grids.lighting, lighting.reshape(grids.lighting.shape))
        self.assertGreater(float(grids.density.max()), 0.0)
        files = sylva.export_grids(sylva.Scene.load(scene_file), 0, self.path("py"), cache=False)
        np.testing.assert_array_equal(np.load(files["lighting"]), lighting)

    def test_progress_and_cancel(self):
        seen = []
        sylva.render(small_scene(), cache=False, progress=lambda f, m: seen.append((f, m)))
        self.assertGreater(len(seen), 5)
        self.assertAlmostEqual(seen[-1][0], 1.0)
        fractions = [f for f, _ in seen]
        self.assertTrue(all(0.0 <= f <= 1.0 for f in fractions))
        self.assertEqual(fractions, sorted(fractions), "progress never runs back")
        # A False answer stops the job.
        with self.assertRaises(sylva.Cancelled):
            sylva.render(small_scene(), cache=False, progress=lambda f, m: False)
        # The callback's exception stops it and comes out as itself.
        def boom(f, m):
            raise ValueError("stop here")
        with self.assertRaisesRegex(ValueError, "stop here"):
            sylva.render(small_scene(), cache=False, progress=boom)
        # A token from another thread.
        token = sylva.CancelToken()
        started = threading.Event()
        outcome = []
        def job():
            big = small_scene()
            big.render.width, big.render.height, big.render.spp = 640, 320, 64
            try:
                sylva.render(big, cache=False, cancel=token, progress=lambda f, m: started.set())
                outcome.append("finished")
            except sylva.Cancelled:
                outcome.append("cancelled")
        t = threading.Thread(target=job)
        t.start()
        self.assertTrue(started.wait(120))
        token.cancel()
        t.join(120)
        self.assertEqual(outcome, ["cancelled"])
        # Nothing is left behind: the next job runs.
        self.assertEqual(sylva.render(small_scene(), cache=False).linear.shape, (32, 64, 3))

    def test_grow_and_import(self):
        obj = self.path("shrub.obj")
        mesh = sylva.grow("shrub", seed=3, triangles=2000, obj=obj)
        self.assertIn(mesh.triangle_count, (1999, 2000))
        self.assertEqual(mesh.triangles.shape, (mesh.triangle_count, 3))
        self.assertLess(int(mesh.triangles.max()), len(mesh.positions))
        self.assertEqual([m["leaf"] for m in mesh.materials], [False, True])
        np.testing.assert_array_equal(sylva.grow("shrub", seed=3, triangles=2000).positions, mesh.positions)
        back = sylva.import_mesh(obj)
        self.assertEqual(back.triangle_count, mesh.triangle_count)
        np.testing.assert_allclose(back.positions.min(axis=0), mesh.positions.min(axis=0), atol=1e-5)
        np.testing.assert_allclose(back.positions.max(axis=0), mesh.positions.max(axis=0), atol=1e-5)
        with self.assertRaisesRegex(sylva.Error, "unknown species 'oak'"):
            sylva.grow("oak")

    def test_gltf_export_keeps_instances(self):
        scene = small_scene()
        scene.add_instances(0, np.array([[4.0, 0.0, 4.0]]), scales=np.array([1.5]))
        out = self.path("two.glb")
        plan = sylva.export_gltf(scene, out)
        self.assertEqual(plan["instances"], 3)
        with open(out, "rb") as f:
            data = f.read()
        magic, version, length = struct.unpack_from("<4sII", data, 0)
        self.assertEqual((magic, version, length), (b"glTF", 2, len(data)))
        chunk_length, chunk_type = struct.unpack_from("<I4s", data, 12)
        self.assertEqual(chunk_type, b"JSON")
        doc = json.loads(data[20:20 + chunk_length])
        counts = [doc["accessors"][n["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"]]["count"]
                  for n in doc["nodes"] if "EXT_mesh_gpu_instancing" in n.get("extensions", {})]
        self.assertEqual(sum(counts), 3)


class Docs(Files):
    def test_batch_example_runs(self):
        """The batch example of docs/PYTHON.md, at a tiny size: a scatter rule in Python and a sun sweep."""
        with open(os.path.join(SOURCE, "docs", "PYTHON.md")) as f:
            text = f.read()
        block = re.search(r"## A batch example.*?```python\n(.*?)```", text, re.S)
        self.assertIsNotNone(block, "docs/PYTHON.md has no batch example")
        code = block.group(1)
        code, n = re.subn(r"^SIZE = .*$", "SIZE = (48, 24)", code, flags=re.M)
        self.assertEqual(n, 1, "the example sets SIZE once")
        code, n = re.subn(r"^ELEVATIONS = .*$", "ELEVATIONS = [20, 60]", code, flags=re.M)
        self.assertEqual(n, 1, "the example sets ELEVATIONS once")
        cwd = os.getcwd()
        os.chdir(self.tmp)
        try:
            exec(compile(code, "docs/PYTHON.md", "exec"), {"__name__": "__main__"})
        finally:
            os.chdir(cwd)
        for e in (20, 60):
            self.assertTrue(os.path.getsize(os.path.join(self.tmp, "sweep", "sun_%02d.png" % e)) > 0)
        saved = sylva.Scene.load(os.path.join(self.tmp, "sweep", "meadow.sylva.json"))
        self.assertGreater(saved.instance_count, 10)


if __name__ == "__main__":
    unittest.main()
