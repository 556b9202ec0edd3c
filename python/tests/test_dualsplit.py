"""The Python package against the command line: the same hits bit for bit, the same
simulate document, the same configuration errors."""

import json
import pathlib

import numpy as np
import pytest

import dualsplit

# A small hairball: thin, overlapping triangles, many ties broken by the closest-hit rule.
SCENE = "builtin:hairball?triangles=4000&seed=3"


@pytest.fixture(scope="module")
def scene():
    return dualsplit.load_scene(SCENE)


def random_rays(scene, n=3000, seed=7):
    """Rays from points around the scene's bounds towards triangles and random points, with
    varied intervals, some starting inside the geometry."""
    rng = np.random.default_rng(seed)
    lo, hi = scene.bounds
    centre, size = (lo + hi) / 2, (hi - lo)
    origins = (centre + size * rng.uniform(-1.0, 1.0, (n, 3))).astype(np.float32)
    # Most rays aim at a triangle's centroid, the rest anywhere in the bounds.
    centroids = scene.triangles.mean(axis=1)
    targets = np.where(
        (rng.uniform(size=n) < 0.7)[:, None],
        centroids[rng.integers(0, len(scene), n)],
        lo + size * rng.uniform(0.0, 1.0, (n, 3)),
    ).astype(np.float32)
    dirs = (targets - origins).astype(np.float32)
    tmin = rng.uniform(0.0, 0.2, n).astype(np.float32)
    tmax = np.where(rng.uniform(size=n) < 0.8, np.inf, rng.uniform(0.3, 2.0, n)).astype(np.float32)
    return origins, dirs, tmin, tmax


def ray_file(path, origins, dirs, tmin, tmax):
    recs = np.concatenate([origins, dirs, tmin[:, None], tmax[:, None]], axis=1).astype("<f4")
    path.write_bytes(recs.tobytes())
    return path


def cli_hits(cli, tmp_path, spec, rays, traversal, tree=None):
    rf = ray_file(tmp_path / "rays.bin", *rays)
    out = tmp_path / f"hits-{traversal}.bin"
    args = ["trace", spec, "--rays", rf, "--accel", traversal, "-o", out]
    if tree is not None:
        args += ["--tree", tree]
    cli(*args)
    rec = np.frombuffer(out.read_bytes(), dtype=[("t", "<f4"), ("prim", "<i4"), ("u", "<f4"), ("v", "<f4")])
    return rec["t"], rec["prim"].astype(np.int64), rec["u"], rec["v"]


def cli_occluded(cli, tmp_path, spec, rays, traversal):
    rf = ray_file(tmp_path / "rays.bin", *rays)
    out = tmp_path / f"occ-{traversal}.bin"
    cli("trace", spec, "--rays", rf, "--accel", traversal, "--occluded", "-o", out)
    return np.frombuffer(out.read_bytes(), dtype=np.uint8).astype(bool)


def same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype.itemsize == b.dtype.itemsize and a.shape == b.shape
    return np.array_equal(a.view(f"u{a.dtype.itemsize}"), b.view(f"u{b.dtype.itemsize}"))


def test_triangles_are_a_read_only_array_of_the_scene(scene):
    tris = scene.triangles
    assert tris.dtype == np.float32 and tris.shape == (len(scene), 3, 3)
    assert len(scene) > 3000
    assert not tris.flags.writeable
    with pytest.raises(ValueError):
        tris[0, 0, 0] = 1.0
    lo, hi = scene.bounds
    assert np.array_equal(lo, tris.reshape(-1, 3).min(axis=0))
    assert np.array_equal(hi, tris.reshape(-1, 3).max(axis=0))
    # Loading twice gives the same triangles (determinism), in new memory.
    again = dualsplit.load_scene(SCENE).triangles
    assert same_bits(tris, again) and not np.shares_memory(tris, again)


@pytest.mark.parametrize(
    "kind,traversal",
    [
        ("bvh2", "bvh2"),
        ("bvh4", "bvh4"),
        ("bvh8", "bvh8"),
        ("dst", "dst-sw"),
        ("dst", "dst"),
        ("cwbvh", "cwbvh"),
        ("dst-q", "dst-q"),
    ],
)
def test_intersect_matches_the_cli_bit_for_bit(cli, tmp_path, scene, kind, traversal):
    rays = random_rays(scene)
    tree = dualsplit.build(scene, kind)
    t, prim, u, v = tree.intersect(*rays, traversal=traversal)
    ct, cprim, cu, cv = cli_hits(cli, tmp_path, SCENE, rays, traversal)
    hits = int((prim >= 0).sum())
    assert 300 < hits < len(prim), "the rays should both hit and miss"
    assert np.array_equal(prim, cprim)
    assert same_bits(t, ct) and same_bits(u, cu) and same_bits(v, cv)
    assert np.all(np.isinf(t[prim < 0])) and np.all(u[prim < 0] == 0)

    occ = tree.occluded(*rays, traversal=traversal)
    assert np.array_equal(occ, cli_occluded(cli, tmp_path, SCENE, rays, traversal))
    assert np.array_equal(occ, prim >= 0)


def test_saved_trees_answer_as_built_and_the_cli_reads_them(cli, tmp_path, scene):
    rays = random_rays(scene, n=1000, seed=11)
    tree = dualsplit.build(scene, "dst")
    path = tmp_path / "scene.dst"
    tree.save(path)
    loaded = dualsplit.Tree.load(path, scene)
    assert loaded.kind == "dst" and loaded.traversals == ["dst-sw", "dst"]
    a, b = tree.intersect(*rays), loaded.intersect(*rays)
    assert all(same_bits(x, y) for x, y in zip(a, b))
    c = cli_hits(cli, tmp_path, SCENE, rays, "dst-sw", tree=path)
    assert all(same_bits(x, y) for x, y in zip(a, c))


def test_scalar_and_per_ray_intervals_agree(scene):
    o, d, _, _ = random_rays(scene, n=500, seed=5)
    tree = dualsplit.build(scene, "bvh8")
    t1 = tree.intersect(o, d, 0.0, np.inf)[0]
    t2 = tree.intersect(o, d, np.zeros(500, np.float32), np.full(500, np.inf, np.float32))[0]
    assert same_bits(t1, t2)
    hit = np.isfinite(t1)
    # An interval that ends just before each hit misses it.
    assert hit.sum() > 100
    t3 = tree.intersect(o[hit], d[hit], 0.0, np.nextafter(t1[hit], np.float32(0)))[0]
    assert np.all(np.isinf(t3))


def test_errors_are_exceptions_with_the_rust_message(tmp_path, scene):
    with pytest.raises(dualsplit.DualsplitError, match="loading scene no/such.obj"):
        dualsplit.load_scene("no/such.obj")
    with pytest.raises(dualsplit.DualsplitError, match="teapot"):
        dualsplit.load_scene("builtin:teapot")
    with pytest.raises(dualsplit.DualsplitError, match="triangles"):
        dualsplit.load_scene(SCENE, max_triangles=10)
    with pytest.raises(ValueError, match="unknown structure `bvh3`"):
        dualsplit.build(scene, "bvh3")
    tree = dualsplit.build(scene, "bvh2")
    o = np.zeros((4, 3), np.float32)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        tree.intersect(np.zeros((4, 2), np.float32), o)
    with pytest.raises(TypeError, match="float32"):
        tree.intersect(np.zeros((4, 3), np.float64), o)
    with pytest.raises(ValueError, match="4 origins but 3 directions"):
        tree.intersect(o, np.zeros((3, 3), np.float32))
    with pytest.raises(ValueError, match="tmax: 2 values for 4 rays"):
        tree.intersect(o, o, 0.0, np.zeros(2, np.float32))
    with pytest.raises(ValueError, match="traversal `dst`"):
        tree.intersect(o, o, traversal="dst")
    # A tree of another scene is refused, naming the file.
    path = tmp_path / "t.bvh2"
    tree.save(path)
    with pytest.raises(dualsplit.DualsplitError, match="t.bvh2"):
        dualsplit.Tree.load(path, "builtin:cornell")
    bad = tmp_path / "bad.tree"
    bad.write_bytes(b"not a tree")
    with pytest.raises(dualsplit.DualsplitError, match="bad.tree"):
        dualsplit.Tree.load(bad, scene)
    with pytest.raises(ValueError, match="unknown configuration `bvh3`"):
        dualsplit.simulate(scene, accel="bvh3", res=8)
    with pytest.raises(ValueError, match="unknown workload"):
        dualsplit.simulate(scene, workload="trace", res=8)


SIM = dict(workload="cast", res=(24, 16), tms=2, model="fast")


def sim_cli(cli, *extra):
    r = cli("simulate", SCENE, "--workload", "cast", "--res", "24x16", "--tms", "2", "--model", "fast", "--json", *extra)
    return json.loads(r.stdout)


def test_simulate_equals_the_cli_json(cli, scene):
    got = dualsplit.simulate(scene, accel=["bvh2", "dst"], **SIM)
    want = sim_cli(cli, "--accel", "bvh2,dst")
    assert got == want
    assert [r["accel"] for r in got["results"]] == ["bvh2", "dst"]
    assert got["summary"]["baseline"] == "bvh2"


def test_simulate_threads_change_no_result(cli, scene):
    one = dualsplit.simulate(scene, accel="dst", threads=1, **SIM)
    assert dualsplit.simulate(scene, accel="dst", threads=2, **SIM) == one
    assert one == sim_cli(cli, "--accel", "dst", "--sim-threads", "2")
    with pytest.raises(ValueError, match="threads"):
        dualsplit.simulate(scene, accel="dst", threads=0, **SIM)


def test_simulate_simt_equals_the_cli_json(cli, scene):
    rtx = pathlib.Path(__file__).resolve().parents[2] / "configs" / "rtx2060.toml"
    got = dualsplit.simulate(scene, accel=["bvh2", "dst"], workload="cast", res=(24, 16), model="simt", config_file=rtx)
    r = cli("simulate", SCENE, "--workload", "cast", "--res", "24x16", "--model", "simt", "--config", str(rtx), "--accel", "bvh2,dst", "--json")
    assert got == json.loads(r.stdout)
    assert all(x["simt"]["rt_max_warps"] == 4 for x in got["results"])
    with pytest.raises((dualsplit.DualsplitError, ValueError), match=r"\[simt\]"):
        dualsplit.simulate(scene, accel="bvh2", res=8, model="simt")


def test_simulate_with_a_saved_tree_equals_the_cli(cli, tmp_path, scene):
    path = tmp_path / "scene.dst"
    dualsplit.build(scene, "dst").save(path)
    got = dualsplit.simulate(scene, tree=dualsplit.Tree.load(path, scene), **SIM)
    want = sim_cli(cli, "--tree", path)
    assert got == want
    assert [r["accel"] for r in got["results"]] == ["dst-sw", "dst"]
    with pytest.raises(dualsplit.DualsplitError, match="bvh2"):
        dualsplit.simulate(scene, tree=dualsplit.Tree.load(path, scene), accel="bvh2", **SIM)


def test_config_overrides_equal_a_config_file(cli, tmp_path, scene):
    toml = tmp_path / "small-l2.toml"
    toml.write_text("[l2]\nsize_bytes = 65536\nbanks = 16\n")
    want = sim_cli(cli, "--config", toml)
    nested = dualsplit.simulate(scene, config={"l2": {"size_bytes": 65536, "banks": 16}}, **SIM)
    dotted = dualsplit.simulate(scene, config={"l2.size_bytes": 65536, "l2.banks": 16}, **SIM)
    assert nested == want and dotted == want
    assert want["config"]["l2"]["size_bytes"] == 65536
    base = dualsplit.simulate(scene, **SIM)
    assert base["results"][0]["dram_lines"] != want["results"][0]["dram_lines"]


@pytest.mark.parametrize(
    "key,value,toml",
    [
        ("l2.size_bytes", 3, "[l2]\nsize_bytes = 3\n"),
        ("units.dst_pipes", 0, "[units]\ndst_pipes = 0\n"),
        ("l1.size_bytes", 3000, "[l1]\nsize_bytes = 3000\n"),
    ],
)
def test_config_range_errors_carry_the_cli_message(cli, tmp_path, scene, key, value, toml):
    path = tmp_path / "bad.toml"
    path.write_text(toml)
    r = cli("simulate", SCENE, "--res", "8", "--config", path, check=False)
    assert r.returncode != 0
    # The CLI's reason, after `in FILE: `, is the configuration's own message.
    reason = r.stderr.strip().split(f"in {path}: ", 1)[1]
    assert reason.startswith("config value")
    with pytest.raises(dualsplit.DualsplitError) as e:
        dualsplit.simulate(scene, res=8, config={key: value})
    assert reason in str(e.value)


def test_config_files_are_read_like_the_cli(cli, tmp_path, scene):
    base = tmp_path / "base.toml"
    base.write_text("[l2]\nsize_bytes = 65536\n")
    got = dualsplit.simulate(scene, config_file=base, config={"l2.banks": 16}, **SIM)
    both = tmp_path / "both.toml"
    both.write_text("[l2]\nsize_bytes = 65536\nbanks = 16\n")
    assert got == sim_cli(cli, "--config", both)
    with pytest.raises(dualsplit.DualsplitError, match="not a regular file"):
        dualsplit.simulate(scene, config_file=tmp_path, res=8)
    with pytest.raises(dualsplit.DualsplitError, match="nope.toml"):
        dualsplit.simulate(scene, config_file=tmp_path / "nope.toml", res=8)


def test_unknown_config_keys_are_refused(scene):
    with pytest.raises(dualsplit.DualsplitError, match="`l2.nope` is not a key of the config TOML"):
        dualsplit.simulate(scene, res=8, config={"l2.nope": 1})
    with pytest.raises(TypeError, match="config"):
        dualsplit.simulate(scene, res=8, config={"tms": [1, 2]})


def test_queries_release_the_gil(scene):
    import threading

    tree = dualsplit.build(scene, "bvh8")
    rays = random_rays(scene, n=200_000, seed=1)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.001)

    th = threading.Thread(target=count)
    th.start()
    try:
        tree.intersect(*rays)
    finally:
        done.set()
        th.join()
    assert len(ticks) > 1


def test_hostile_inputs_raise_dualsplit_errors(tmp_path, scene):
    """Each once aborted the interpreter, answered differently per structure, or named
    another file."""
    import os

    # A dict that contains itself overflowed the Rust stack.
    d = {}
    d["x"] = d
    with pytest.raises(dualsplit.DualsplitError, match="nested more than 4 levels"):
        dualsplit.simulate(scene, config=d, **SIM)
    deep = {"a": {"b": {"c": {"d": {"e": 1}}}}}
    with pytest.raises(dualsplit.DualsplitError, match="nested more than 4 levels"):
        dualsplit.simulate(scene, config=deep, **SIM)
    # Rays that are not traceable are refused by index and field, for every structure.
    o = np.zeros((3, 3), np.float32)
    dirs = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (3, 1))
    tmax = np.array([1.0, np.nan, 1.0], np.float32)
    for kind in ["bvh2", "bvh4", "bvh8", "dst", "cwbvh", "dst-q"]:
        tree = dualsplit.build(scene, kind)
        with pytest.raises(dualsplit.DualsplitError, match="ray 1: t_max is NaN"):
            tree.intersect(o, dirs, 0.0, tmax)
        with pytest.raises(dualsplit.DualsplitError, match="ray 1: t_max is NaN"):
            tree.occluded(o, dirs, 0.0, tmax)
        bad = o.copy()
        bad[2, 0] = np.inf
        with pytest.raises(dualsplit.DualsplitError, match="ray 2: origin.x is inf"):
            tree.intersect(bad, dirs)
        with pytest.raises(dualsplit.DualsplitError, match="ray 0: dir.x is NaN"):
            tree.occluded(o, np.full((3, 3), np.nan, np.float32))
        with pytest.raises(dualsplit.DualsplitError, match="ray 0: t_min is NaN"):
            tree.intersect(o, dirs, np.nan)
    # A name that is not UTF-8 once became another name through a lossy conversion.
    name = os.fsdecode(b"scene-\xff.obj")
    for arg in [name, tmp_path / name]:
        with pytest.raises(dualsplit.DualsplitError, match="not valid UTF-8"):
            dualsplit.load_scene(arg)
