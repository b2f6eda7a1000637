"""The nscdd Python module (docs/PYTHON.md): scenes from files, text and dicts,
stepping, arrays, errors as exceptions, restarts, Ctrl-C, solve_fc, and results
bitwise equal to the command line's."""

import json
import os
import pathlib
import signal
import subprocess

import numpy as np
import pytest

import nscdd

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = pathlib.Path(os.environ.get("NSCDD_BIN", ROOT / "target" / "release" / "nscdd"))


def deposit(count=60, steps=120, **extra):
    """A small deposit of disks in a box, as a dict scene."""
    s = {
        "time": {"step": 1e-3, "theta": 0.5, "steps": steps},
        "solver": {"tolerance": 1.666e-4, "norm": "QM/16", "max_sweeps": 2000, "check_every": 10},
        "output": {"every": 50},
        "materials": [{"name": "grain", "density": 2600.0}, {"name": "steel", "density": 7800.0}],
        "laws": [
            {"materials": ["grain", "grain"], "friction": 0.4},
            {"materials": ["grain", "steel"], "friction": 0.2},
        ],
        "bodies": [
            {"name": "floor", "shape": "wall", "material": "steel", "position": [0.15, -0.01], "length": 0.34, "thickness": 0.02, "fixed": True},
            {"name": "left", "shape": "wall", "material": "steel", "position": [-0.01, 0.2], "rotation": np.pi / 2, "length": 0.4, "thickness": 0.02, "fixed": True},
            {"name": "right", "shape": "wall", "material": "steel", "position": [0.31, 0.2], "rotation": np.pi / 2, "length": 0.4, "thickness": 0.02, "fixed": True},
        ],
        "generate": [
            {"kind": "disk_deposit", "material": "grain", "count": count, "radius_min": 0.008, "radius_max": 0.012, "box": [0.0, 0.0, 0.3, 0.35], "seed": 1}
        ],
    }
    s.update(extra)
    return s


SPHERES = {
    "dimension": 3,
    "gravity": [0.0, 0.0, -9.81],
    "time": {"step": 1e-3, "steps": 40},
    "materials": [{"name": "grain", "density": 2600.0}],
    "laws": [{"materials": ["grain", "grain"], "friction": 0.3}],
    "bodies": [
        {"name": "floor", "shape": "plane", "material": "grain", "position": [0.0, 0.0, 0.0], "fixed": True},
        {"shape": "sphere", "material": "grain", "radius": 0.01, "position": [0.0, 0.0, 0.0105]},
        {"shape": "sphere", "material": "grain", "radius": 0.01, "position": [0.0, 0.0, 0.031]},
    ],
}


def test_a_dict_scene_steps_and_reports():
    sim = nscdd.Simulation(deposit())
    assert sim.dimension == 2 and sim.current_step == 0 and sim.total_steps == 120
    assert sim.n_bodies == 63
    r = sim.step()
    assert r["step"] == 1 and r["time"] == pytest.approx(1e-3)
    assert set(r) == {"step", "time", "contacts", "sweeps", "converged", "residual"}
    assert "63 bodies" in repr(sim)


def test_arrays_have_the_bodies_shapes():
    sim = nscdd.Simulation(deposit())
    sim.run(30, progress=False)
    n = sim.n_bodies
    assert sim.positions().shape == (n, 2)
    assert sim.velocities().shape == (n, 2)
    assert sim.angular_velocities().shape == (n,)
    assert sim.rotations().shape == (n,)
    r = sim.radii()
    assert r.shape == (n,) and np.all((r[3:] >= 0.008) & (r[3:] <= 0.012))
    assert np.all(sim.masses()[3:] > 0)
    assert sim.names()[:3] == ["floor", "left", "right"] and sim.names()[3] is None
    sh = sim.shapes()
    kinds = [sh["kinds"][k] for k in sh["kind"]]
    assert kinds[:3] == ["wall"] * 3 and set(kinds[3:]) == {"disk"} and sh["shape"].shape == (n,)
    assert sim.body("right") == 2
    # copies: an array kept across steps stays what it was
    x = sim.positions()
    x0 = x.copy()
    sim.step()
    assert np.array_equal(x, x0) and not np.array_equal(sim.positions(), x0)
    c = sim.contacts()
    m = len(c["gap"])
    assert m > 0 and c["bodies"].shape == (m, 2) and c["point"].shape == (m, 2)
    assert c["normal"].shape == (m, 2) and c["r"].shape == (m, 2) and c["bonded"].dtype == bool
    assert np.allclose(np.linalg.norm(c["normal"], axis=1), 1.0)


def test_a_3d_scene():
    sim = nscdd.Simulation(SPHERES)
    assert sim.dimension == 3
    sim.run(progress=False)
    assert sim.positions().shape == (3, 3) and sim.rotations().shape == (3, 3)
    # the spheres rest on the floor and on one another
    z = sim.positions()[1:, 2]
    assert z == pytest.approx([0.01, 0.03], abs=2e-4)
    assert len(sim.contacts()["gap"]) == 2


def test_history_as_arrays_and_frame():
    sim = nscdd.Simulation(deposit(steps=20))
    sim.run(progress=False)
    h = sim.history()
    assert len(h["step"]) == 20 and h["step"][-1] == 20
    assert {"time", "contacts", "sweeps", "converged"} <= set(h)
    pd = pytest.importorskip("pandas")
    f = sim.history(as_frame=True)
    assert isinstance(f, pd.DataFrame) and len(f) == 20


def test_callbacks_every_k_steps():
    seen = []
    sim = nscdd.Simulation(deposit(steps=50))
    sim.run(25, callback=lambda s: seen.append(s.current_step), every=10, progress=False)
    assert seen == [10, 20, 25]
    assert not sim.finished
    sim.run(progress=False)
    assert sim.finished and sim.current_step == 50
    with pytest.raises(nscdd.RunError, match="finished"):
        sim.step()


def test_run_past_the_scenes_end_extends_it():
    sim = nscdd.Simulation(deposit(steps=10))
    sim.run(15, progress=False)
    assert sim.current_step == 15 and sim.total_steps == 15


@pytest.mark.parametrize(
    "change, key",
    [
        ({"time": {"step": -1.0, "steps": 5}}, "time.step"),
        ({"solver": {"tolerance": 1e-4, "norm": "Quadratic"}}, "solver.norm"),
        ({"time": {"step": 1e-3, "steps": 5, "stpes": 3}}, "stpes"),
    ],
)
def test_bad_scenes_raise_scene_errors_naming_the_key(change, key):
    with pytest.raises(nscdd.SceneError, match=key.replace(".", r"\.")):
        nscdd.Simulation(deposit(**change))
    assert issubclass(nscdd.SceneError, ValueError)


def test_bad_inputs():
    with pytest.raises(nscdd.SceneError, match="cannot read"):
        nscdd.Simulation("/no/such/scene.toml")
    with pytest.raises(TypeError, match="materials"):
        nscdd.Simulation(deposit(materials=[{"name": "grain", "density": object()}]))
    with pytest.raises(nscdd.SceneError, match="steps"):
        nscdd.Simulation.from_toml("[time]\nstep = 1e-3\nsteps = -2\n")
    sim = nscdd.Simulation(deposit())
    with pytest.raises(ValueError, match="no body named"):
        sim.body("lid")


def test_a_file_scene_and_text_scene_are_the_same(tmp_path):
    text = (ROOT / "examples" / "scenes" / "deposit.toml").read_text().replace("steps = 2000", "steps = 30")
    p = tmp_path / "dep.toml"
    p.write_text(text)
    a, b = nscdd.Simulation(str(p)), nscdd.Simulation.from_toml(text)
    a.run(progress=False)
    b.run(progress=False)
    assert np.array_equal(a.positions(), b.positions())


@pytest.mark.skipif(not CLI.exists(), reason="the nscdd command-line program is not built")
def test_results_are_bitwise_the_command_lines(tmp_path):
    text = (ROOT / "examples" / "scenes" / "deposit.toml").read_text().replace("steps = 2000", "steps = 200")
    scene = tmp_path / "dep.toml"
    scene.write_text(text)
    subprocess.run([str(CLI), "run", str(scene), "--out", str(tmp_path / "cli"), "--quiet"], check=True)
    sim = nscdd.Simulation(str(scene), out=str(tmp_path / "py"))
    sim.step()
    sim.run(progress=False)
    for f in ["final.json", "bodies.pvd"]:
        assert (tmp_path / "cli" / f).read_bytes() == (tmp_path / "py" / f).read_bytes(), f
    # history.csv: the same columns and values, but for the timings
    cli = (tmp_path / "cli" / "history.csv").read_text().splitlines()
    py = (tmp_path / "py" / "history.csv").read_text().splitlines()
    assert cli[0] == py[0] and len(cli) == len(py) == 201
    cols = cli[0].split(",")
    keep = [i for i, c in enumerate(cols) if not c.startswith("t_")]
    for a, b in zip(cli[1:], py[1:]):
        assert [a.split(",")[i] for i in keep] == [b.split(",")[i] for i in keep]


def test_a_restart_continues_bitwise(tmp_path):
    straight = nscdd.Simulation(deposit())
    straight.run(progress=False)
    first = nscdd.Simulation(deposit())
    first.run(70, progress=False)
    first.save(str(tmp_path / "state.json"))
    again = nscdd.Simulation(deposit(), restart=str(tmp_path / "state.json"))
    assert again.current_step == 70
    again.run(progress=False)
    assert np.array_equal(again.positions(), straight.positions())
    assert np.array_equal(again.velocities(), straight.velocities())


def test_drives_change_between_steps():
    s = deposit(steps=40)
    s["laws"].append({"materials": ["steel", "steel"], "law": "none"})
    s["bodies"].append({"name": "lid", "shape": "wall", "material": "steel", "position": [0.15, 0.45], "length": 0.28, "thickness": 0.02, "drive": {"x": {"velocity": 0.0}, "y": {"velocity": 0.0}, "rot": {"velocity": 0.0}}})
    sim = nscdd.Simulation(s)
    lid = sim.body("lid")
    sim.run(5, progress=False)
    y0 = sim.positions()[lid, 1]
    sim.set_drive("lid", "y", {"velocity": -0.1})
    sim.run(10, progress=False)
    assert sim.velocities()[lid, 1] == pytest.approx(-0.1)
    # θ = ½: the first step moves by h (v⁻ + v⁺)/2
    assert sim.positions()[lid, 1] == pytest.approx(y0 - 0.1 * 9.5e-3, rel=1e-9)
    sim.set_drive(lid, "y", [{"velocity": 0.0, "until": 0.5}])
    sim.step()
    assert sim.velocities()[lid, 1] == 0.0
    with pytest.raises(ValueError, match="degree of freedom"):
        sim.set_drive("lid", "z", {"velocity": 0.0})
    with pytest.raises(ValueError, match="no drive"):
        sim.set_drive(5, "y", {"velocity": 0.0})
    with pytest.raises(ValueError, match="drive"):
        sim.set_drive("lid", "y", {"speed": 1.0})


def test_ctrl_c_stops_after_the_step_keeping_a_checkpoint(tmp_path):
    sim = nscdd.Simulation(deposit(steps=100), out=str(tmp_path))

    def interrupt(s):
        if s.current_step == 30:
            # to this thread (a process-directed kill may land on a worker thread)
            signal.raise_signal(signal.SIGINT)

    # Python's own handler, even where SIGINT was ignored when it started (a
    # background job of a non-interactive shell)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(callback=interrupt, progress=False)
    finally:
        signal.signal(signal.SIGINT, previous)
    state = json.loads((tmp_path / "checkpoint.json").read_text())
    assert state["step"] in (30, 31) and sim.current_step == state["step"]
    assert len((tmp_path / "history.csv").read_text().splitlines()) == state["step"] + 1


def random_problem(nc=40, dim=2, seed=3):
    """A positive definite W (a random H M⁻¹ Hᵀ) and a q that closes contacts."""
    rng = np.random.default_rng(seed)
    n = dim * nc
    h = rng.normal(size=(n, n + 10))
    W = h @ h.T / n + 0.1 * np.eye(n)
    q = rng.normal(size=n)
    q[::dim] -= 0.5
    return W, q, np.full(nc, 0.3)


@pytest.mark.parametrize("method,relaxation", [("nlgs", 1.0), ("anderson", 1.0), ("newton", 1.0), ("nlgs", 1.2), ("anderson", 1.3)])
def test_solve_fc_reaches_its_tolerance(method, relaxation):
    W, q, mu = random_problem()
    s = nscdd.solve_fc(W, q, mu, method=method, tol=1e-8, relaxation=relaxation)
    assert s["converged"] and s["residual"] < 1e-8
    r, u = s["r"].reshape(-1, 2), s["u"].reshape(-1, 2)
    assert np.allclose(u.ravel(), W @ s["r"] + q, atol=1e-9)
    # Coulomb: r in the cone, u_n ≥ 0, complementarity
    assert np.all(r[:, 0] >= -1e-12) and np.all(np.abs(r[:, 1]) <= 0.3 * r[:, 0] + 1e-9)
    assert np.all(u[:, 0] >= -1e-6) and np.all(np.abs(r[:, 0] * u[:, 0]) < 1e-6)


def test_solve_fc_takes_sparse_matrices_and_a_warm_start():
    sp = pytest.importorskip("scipy.sparse")
    W, q, mu = random_problem(dim=3, nc=20)
    dense = nscdd.solve_fc(W, q, mu, tol=1e-10)
    sparse = nscdd.solve_fc(sp.csr_matrix(W), q, mu, tol=1e-10)
    assert np.allclose(dense["r"], sparse["r"], atol=1e-8)
    warm = nscdd.solve_fc(W, q, mu, tol=1e-10, r0=dense["r"])
    assert warm["sweeps"] <= 2
    with pytest.raises(ValueError, match="method"):
        nscdd.solve_fc(W, q, mu, method="pgs")
    with pytest.raises(ValueError, match="contacts"):
        nscdd.solve_fc(W, q[:-1], mu)
    with pytest.raises(ValueError, match="relaxation"):
        nscdd.solve_fc(W, q, mu, relaxation=2.0)
    with pytest.raises(ValueError, match="relaxation"):
        nscdd.solve_fc(W, q, mu, method="newton", relaxation=1.2)


def test_the_stubs_name_every_method():
    import re

    stub = (pathlib.Path(nscdd.__file__).parent / "_nscdd.pyi").read_text()
    named = set(re.findall(r"def (\w+)\(", stub))
    public = {m for m in dir(nscdd.Simulation) if not m.startswith("_")}
    assert public <= named, public - named
    assert (pathlib.Path(nscdd.__file__).parent / "py.typed").exists()


@pytest.mark.parametrize("example", ["arch.py", "deposit.py"])
def test_examples_run(example, tmp_path):
    """The notebook-ready examples (the two short ones; biaxial.py and
    mu_sweep.py take 10–40 s and are run by hand)."""
    import sys

    out = subprocess.run([sys.executable, str(ROOT / "python" / "examples" / example)], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip()


def test_subdomain_ids_with_a_decomposition():
    sim = nscdd.Simulation(deposit(decomposition={"nx": 2, "ny": 1}))
    assert sim.subdomains() is None
    sim.run(20, progress=False)
    d = sim.subdomains()
    m = len(sim.contacts()["gap"])
    assert d["contacts"].shape == (m,) and set(d["contacts"]) == {0, 1}
    assert d["bodies"].shape == (sim.n_bodies,) and d["bodies"].min() >= -1
    assert np.all(d["copies"][d["bodies"] >= 0] >= 1)
    # the same scene without a decomposition has none
    plain = nscdd.Simulation(deposit())
    plain.step()
    assert plain.subdomains() is None


def polygon_scene(library):
    s = deposit(steps=10)
    s["plugins"] = [{"library": str(library)}]
    s["generate"] = []
    s["bodies"].append({"shape": "polygon", "sides": 5, "radius": 0.01, "material": "grain", "position": [0.15, 0.1]})
    return s


# built with the module by scripts/python_with_plugins.sh (scripts/test.sh)
WITH_MODULE = ROOT / "target" / "python" / "libnscdd_polygons.so"
# built by `cargo test` with the command line's features
WITH_CLI = ROOT / "target" / "release" / "deps" / "libnscdd_polygons.so"


@pytest.mark.skipif(not WITH_MODULE.exists(), reason="scripts/python_with_plugins.sh nscdd-polygons was not run")
def test_a_scene_loads_its_run_time_plugins():
    sim = nscdd.Simulation(polygon_scene(WITH_MODULE))
    sim.run(progress=False)
    assert sim.positions()[-1, 1] < 0.1
    assert sim.shapes()["kinds"] == ["wall", "polygon"]


@pytest.mark.skipif(not WITH_CLI.exists(), reason="the polygons plugin library is not built")
def test_a_plugin_of_another_build_is_refused():
    try:
        nscdd.Simulation(polygon_scene(WITH_CLI))
    except nscdd.SceneError as e:
        assert "plugins[0].library" in str(e) and ("framework features" in str(e) or "another build" in str(e)), e
        return
    raise AssertionError("the command line's plugin library was loaded by the module")


@pytest.mark.skipif(not CLI.exists(), reason="the nscdd command-line program is not built")
def test_deformable_bodies_bitwise_the_command_lines(tmp_path):
    """The fem plugin (deformable bodies through scikit-fem, imported in the running
    Python): the foundation example by model in 2 subdomains."""
    pytest.importorskip("skfem")
    text = (ROOT / "examples" / "scenes" / "foundation.toml").read_text().replace("duration = 0.5", "duration = 0.04")
    scene = tmp_path / "foundation.toml"
    scene.write_text(text)
    env = dict(os.environ, NSCDD_PYTHON_ENV=str(pathlib.Path(os.sys.prefix)))
    subprocess.run([str(CLI), "run", str(scene), "--out", str(tmp_path / "cli"), "--quiet"], check=True, env=env)
    sim = nscdd.Simulation(str(scene), out=str(tmp_path / "py"))
    sim.run(progress=False)
    assert "kinetic_deformable" in sim.history()
    assert (tmp_path / "cli" / "final.json").read_bytes() == (tmp_path / "py" / "final.json").read_bytes()


def test_gravity_changes_between_steps():
    sim = nscdd.Simulation(SPHERES)
    assert sim.gravity == [0.0, 0.0, -9.81]
    sim.step()
    sim.gravity = [0.0, 0.0, 9.81]  # up: the top sphere leaves
    sim.run(10, progress=False)
    assert sim.velocities()[2, 2] > 0.05
    with pytest.raises(ValueError, match="3 finite numbers"):
        sim.gravity = [0.0, 1.0]


def test_review_edge_cases(tmp_path):
    # a restart may not write where its state is
    first = nscdd.Simulation(deposit(steps=20), out=str(tmp_path / "a"))
    first.run(progress=False)
    with pytest.raises(nscdd.SceneError, match="holds the restart file"):
        nscdd.Simulation(deposit(steps=40), out=str(tmp_path / "a"), restart=str(tmp_path / "a" / "final.json"))
    # save and subdomains after the end; the summary is kept
    assert first.finished
    first.save(str(tmp_path / "new" / "again.json"))
    assert json.loads((tmp_path / "new" / "again.json").read_text())["step"] == 20
    assert first.finish()["steps"] == 20
    # a setting the scene's run cannot use is a scene error at once
    with pytest.raises(nscdd.SceneError, match="solver.ordering"):
        nscdd.Simulation(deposit(solver={"ordering": "scrambled"}, decomposition={"nx": 2}))
    # the contacts visited from the bottom up: sort_direction with "sorted" only
    with pytest.raises(nscdd.SceneError, match="solver.sort_direction"):
        nscdd.Simulation(deposit(solver={"sort_direction": [0.0, 1.0]}))
    up = nscdd.Simulation(deposit(steps=30, solver={"ordering": "sorted", "sort_direction": [0.0, 2.0]}), out=str(tmp_path / "up"))
    assert up.run(progress=False)["steps"] == 30
    # finish before the scene's end writes the last frame
    sim = nscdd.Simulation(deposit(steps=200), out=str(tmp_path / "b"))
    s = sim.run(25, progress=False)
    assert s["steps"] == 25 and s["wall_seconds"] > 0
    sim.finish()
    frames = sorted(p.name for p in (tmp_path / "b" / "vtk").glob("bodies_*"))
    assert len(frames) == 2, frames
    # history: counts as integers, `prevailing` as text
    dd = nscdd.Simulation(deposit(steps=5, decomposition={"nx": 2}))
    dd.run(progress=False)
    h = dd.history()
    assert h["step"].dtype == np.int64 and h["converged"].dtype == np.int64 and h["time"].dtype == np.float64
    assert h["prevailing"].dtype.kind == "U"
    assert len(nscdd.Simulation(deposit()).history()["step"]) == 0


def test_a_callback_may_step_the_simulation():
    seen = []

    def cb(s):
        seen.append(s.current_step)
        if s.current_step == 10:
            s.step()

    sim = nscdd.Simulation(deposit(steps=30))
    sim.run(callback=cb, every=10, progress=False)
    assert sim.current_step == 30 and sim.finished and seen[:2] == [10, 20]


def test_live_views_follow_the_simulation_without_copies():
    sim = nscdd.Simulation(deposit())
    x, v, w = sim.positions(copy=False), sim.velocities(copy=False), sim.angular_velocities(copy=False)
    assert x.shape == (sim.n_bodies, 2) and v.shape == (sim.n_bodies, 2) and w.shape == (sim.n_bodies,)
    assert not x.flags.writeable and not x.flags.owndata
    with pytest.raises(ValueError):
        x[3, 1] = 0.0
    sim.run(20, progress=False)
    # the views show the state after the last step
    assert np.array_equal(x, sim.positions()) and np.array_equal(v, sim.velocities())
    assert np.array_equal(w, sim.angular_velocities())
    # a view keeps its simulation alive
    del sim
    import gc

    gc.collect()
    assert np.all(np.isfinite(x))
    s3 = nscdd.Simulation(SPHERES)
    s3.run(5, progress=False)
    assert np.array_equal(s3.angular_velocities(copy=False), s3.angular_velocities())
