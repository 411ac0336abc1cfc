"""A renderer test harness's use of the installed bdptref Python module (docs/library.md):
compare a NumPy image with a reference, check the MIS weights of a path, round-trip a film and
render a scene in-process. Run: PYTHONPATH=PREFIX/lib/python3/dist-packages /usr/bin/python3 -m pytest
examples/pytest (BDPTREF_SCENES=<repo>/scenes for the rendering test).

Statistical checks use fixed seeds (deterministic); each states its tolerance."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import bdptref

H, W = 32, 32


def reference_image():
    """A smooth reference with per-pixel variance of the mean (as a converged render has)."""
    y, x = np.mgrid[0:H, 0:W]
    mean = np.stack([0.2 + 0.5 * x / W, 0.3 + 0.4 * y / H, np.full((H, W), 0.6)], axis=-1).astype(np.float32)
    variance = np.full((H, W, 3), 1e-4, dtype=np.float32)
    return mean, variance


@pytest.fixture
def scenes():
    """The repository's scenes/ folder (BDPTREF_SCENES); the tests that render skip without it."""
    folder = os.environ.get("BDPTREF_SCENES")
    if not folder:
        pytest.skip("BDPTREF_SCENES (the repository's scenes/ folder) is not set")
    return folder


def scene_only(path):
    """A traced path's vertices by positions, normals, materials and lights only (NumPy arrays): no
    densities, so that mis_weights evaluates them from the scene."""
    out = {"scene": path["scene"], "mis": path["mis"], "vertices": []}
    for v in path["vertices"]:
        w = {k: v[k] for k in ("type", "material", "light", "delta", "infinite") if k in v}
        for k in ("p", "ng", "ns", "uv"):
            if k in v:
                w[k] = np.array(v[k])
        out["vertices"].append(w)
    return out


def contributed_connections(scenes, tmp_path, *extra):
    """The contributed connections of one `bdptref trace` of mis-zoo (every light type and an environment)."""
    trace = str(tmp_path / "trace.json")
    subprocess.run([sys.executable, "-m", "bdptref", "trace", os.path.join(scenes, "mis-zoo.gltf"), "--pixel", "12,12",
                    "--sample", "7", "--width", "24", "--height", "24", "--env", "0.3,0.35,0.4", "--seed", "3",
                    "--max-depth", "6", *extra, "-o", trace], check=True, capture_output=True)
    with open(trace) as f:
        return [c for c in json.load(f)["connections"] if c["status"] == "contributed"]


def noisy_render(mean, sigma, rng):
    return (mean + rng.normal(0.0, sigma, mean.shape)).astype(np.float32)


def test_compare_numpy_image_consistent_with_reference():
    mean, variance = reference_image()
    rng = np.random.default_rng(17)
    test_var = np.full_like(variance, 4e-4)
    test = noisy_render(mean, np.sqrt(test_var + variance), rng)  # unbiased: noise of both images
    r = bdptref.compare(test, mean, test_variance=test_var, reference_variance=variance)
    assert r.has_verdict and r.test_kind == "welch"
    assert r.consistent, r.sentence
    assert r.p_value >= 0.01
    assert r.flagged_mask.shape == (H, W)


def test_compare_detects_a_biased_region():
    mean, variance = reference_image()
    rng = np.random.default_rng(18)
    test_var = np.full_like(variance, 4e-4)
    test = noisy_render(mean, np.sqrt(test_var + variance), rng)
    # +0.25 in an 8x8 block: 11 sigma of the difference (sqrt(5e-4) = 0.022) in every pixel.
    test[4:12, 20:28, :] += 0.25
    r = bdptref.compare(test, mean, test_variance=test_var, reference_variance=variance)
    assert r.has_verdict and not r.consistent and not r
    assert r.p_value < 1e-6
    inside = np.zeros((H, W), dtype=bool)
    inside[4:12, 20:28] = True
    assert (r.flagged_mask & inside).sum() >= 60  # nearly all 64 pixels of the block
    # Flagging controls the false discovery rate at alpha = 1% (Benjamini-Hochberg): a few flagged
    # pixels outside the block are allowed; more than 5x alpha of the discoveries would not be.
    assert (r.flagged_mask & ~inside).sum() <= 0.05 * r.flagged_mask.sum()


def test_compare_set_of_renders():
    mean, variance = reference_image()
    rng = np.random.default_rng(19)
    renders = [bdptref.image(noisy_render(mean, np.sqrt(2 * variance), rng), variance) for _ in range(3)]
    s = bdptref.compare_set(renders, bdptref.image(mean, variance))
    assert s.has_verdict and s.consistent, s.sentence
    assert len(s.results) == 3 and 0 <= s.worst < 3


def hand_weights(pc, pl, nee, beta):
    """p_s = prod_{i<t} pc_i * (s=1: nee | s>=2: pl_{n-1}) * prod_{t<=k<n-1} pl_k (docs/mis.md)."""
    n = len(pc)
    p = []
    for s in range(n):
        t = n - s
        v = np.prod(pc[:t])
        if s == 1:
            v *= nee
        if s >= 2:
            v *= pl[n - 1]
        v *= np.prod(pl[t:n - 1])
        p.append(v ** beta)
    p = np.array(p)
    return p / p.sum()


PC = np.array([1.0, 2.5e-2, 3.0e-1, 4.0e-2])
PL = np.array([0.0, 6.0e-3, 2.0e-1, 5.0e-2])
NEE = 8.0e-2


@pytest.mark.parametrize("heuristic,beta", [("balance", 1.0), ("power", 2.0), ("power", 3.5)])
def test_mis_weights_from_densities(heuristic, beta):
    r = bdptref.mis_weights_densities(PC, PL, NEE, heuristic=heuristic, beta=beta)
    assert r["form"] == "densities"
    assert r["valid"].all()
    # Exact closed forms on both sides: 1e-12 relative is ~1000x their rounding.
    np.testing.assert_allclose(r["weights"], hand_weights(PC, PL, NEE, beta), rtol=1e-12)
    assert abs(r["weights"].sum() - 1.0) < 1e-12 and abs(r["sum"] - 1.0) < 1e-12


def test_mis_weights_of_a_path_dict_with_numpy_arrays():
    # The densities form of the "bdptref-path" JSON (what `bdptref mis` reads), built with NumPy.
    vertices = [{"type": "camera", "p": np.zeros(3)}]
    for i in range(1, 3):
        vertices.append({"type": "surface", "p": np.array([0.0, 0.0, float(i)]), "ng": np.array([0.0, 1.0, 0.0]), "material": 0,
                         "pdfCamera": PC[i], "pdfLight": PL[i]})
    vertices.append({"type": "light", "p": np.array([0.0, 0.0, 3.0]), "ng": np.array([0.0, -1.0, 0.0]), "light": 0,
                     "pdfCamera": PC[3], "pdfLight": PL[3], "pdfNextEvent": NEE})
    path = {"format": "bdptref-path", "version": 1, "vertices": vertices}
    r = bdptref.mis_weights(path, form="densities")
    np.testing.assert_allclose(r["weights"], hand_weights(PC, PL, NEE, 1.0), rtol=1e-12)
    assert abs(r["sum"] - 1.0) < 1e-12


def test_mis_weights_of_a_traced_path_against_its_scene(tmp_path, scenes):
    """Scene form: a path given by positions, normals, materials and lights (here one `bdptref trace`
    recorded, rebuilt with NumPy arrays) gets the weights of the definition, bit for bit."""
    connections = contributed_connections(scenes, tmp_path, "--mis", "power")
    assert connections
    for c in connections[:3]:
        r = bdptref.mis_weights(scene_only(c["path"]))
        assert r["form"] == "scene" and r["heuristic"] == "power"
        np.testing.assert_array_equal(r["weights"], np.array(c["definitionWeights"]))
        assert abs(r["sum"] - 1.0) < 1e-12


def test_mis_weights_with_the_light_tree(tmp_path, scenes):
    """A path traced with --light-sampler tree records it: its weights are the trace's, bit for bit;
    light_sampler="power" overrides the record and changes the weights of paths whose next-event
    strategy the tree samples with another probability (s' = 1: docs/mis.md, "Light tree in BDPT")."""
    connections = contributed_connections(scenes, tmp_path, "--light-sampler", "tree")
    assert connections
    changed = 0
    for c in connections:
        path = scene_only(c["path"])
        tree = bdptref.mis_weights(path)
        np.testing.assert_array_equal(tree["weights"], np.array(c["definitionWeights"]))
        power = bdptref.mis_weights(path, light_sampler="power")
        assert abs(power["sum"] - 1.0) < 1e-12
        changed += not np.array_equal(power["weights"], tree["weights"])
    assert changed > 0  # the override reached the weights
    with pytest.raises(bdptref.InputError, match="light_sampler"):
        bdptref.mis_weights(scene_only(connections[0]["path"]), light_sampler="bvh")


def test_bad_input_raises_input_error_with_cli_message():
    with pytest.raises(bdptref.InputError, match="densities must be >= 0"):
        bdptref.mis_weights_densities(PC, -PL, NEE)
    with pytest.raises(bdptref.InputError, match="no-such-file.exr"):
        bdptref.read_film("no-such-file.exr")


def test_film_round_trip_records_the_version(tmp_path):
    film = bdptref.Film(4, 3)
    rng = np.random.default_rng(5)
    for _ in range(5):
        film.add_pass(rng.uniform(0, 1, (3, 4, 3)))
    out = str(tmp_path / "film.exr")
    bdptref.write_film(out, film, {"myharness:run": "unit", "myharness:n": 5})
    back = bdptref.read_film(out)
    assert back.attributes["bdptref:version"] == bdptref.__version__
    assert back.attributes["myharness:run"] == "unit"
    np.testing.assert_array_equal(back.film.mean, film.mean)  # bit for bit (exact state)
    np.testing.assert_array_equal(back.film.count, np.full((3, 4), 5))


def test_render_in_process_and_compare_two_seeds(scenes):
    scene = bdptref.load_scene(os.path.join(scenes, "cornell-box.gltf"), width=16, height=16)
    a = bdptref.render(scene, spp=64, seed=1, max_depth=4, threads=2)
    b = bdptref.render(scene, spp=64, seed=2, max_depth=4, threads=2)
    assert a.mean.shape == (16, 16, 3) and (a.count == 64).all()
    assert np.isfinite(a.mean).all() and a.mean.sum() > 0
    r = bdptref.compare(a, b)
    assert r.has_verdict and r.consistent, r.sentence


def test_render_with_the_light_tree_agrees_with_power_sampling(scenes):
    # Both samplers are unbiased: the same scene rendered with each is consistent by compare
    # (its own calibrated test at alpha = 0.01; fixed seeds). Light tracing refuses the tree.
    scene = bdptref.load_scene(os.path.join(scenes, "mis-zoo.gltf"), width=16, height=16)
    power = bdptref.render(scene, spp=64, seed=1, max_depth=4, threads=2)
    tree = bdptref.render(scene, spp=64, seed=2, max_depth=4, threads=2, light_sampler="tree")
    assert np.isfinite(tree.mean).all() and tree.mean.sum() > 0
    r = bdptref.compare(tree, power)
    assert r.has_verdict and r.consistent, r.sentence
    with pytest.raises(bdptref.InputError):
        bdptref.render(scene, integrator="lt", spp=1, light_sampler="tree")
    with pytest.raises(bdptref.InputError):
        bdptref.render(scene, spp=1, light_sampler="bvh")


def test_python_m_bdptref_runs_the_cli():
    out = subprocess.run([sys.executable, "-m", "bdptref", "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.startswith("bdptref " + bdptref.__version__)
