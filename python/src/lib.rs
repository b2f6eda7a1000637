//! `nscdd._nscdd`: the Rust half of the `nscdd` Python module (docs/PYTHON.md).
//! `Simulation` loads a scene (a TOML file, TOML text, or dicts), steps it with
//! the GIL released, and gives its state as NumPy arrays; `solve_fc` solves one
//! frictional contact problem. The package `python/nscdd` wraps it (progress bars,
//! pandas).

mod fc;
mod sim;
mod toml_of;

use nscdd::dim::{D2, D3};
use nscdd::registry::Registry;
use nscdd::scene::AnyScene;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim::Sim;
use std::path::PathBuf;

pyo3::create_exception!(
    _nscdd,
    SceneError,
    PyValueError,
    "A scene that cannot be loaded: the message names the file, line and key."
);
pyo3::create_exception!(
    _nscdd,
    RunError,
    PyRuntimeError,
    "A run that stopped: a diverging body (step and body named), an output that cannot be written."
);

/// The built-in plugins: rigid disks and walls (2D), spheres, planes and boxes
/// (3D), polyhedra, and with the feature `fem` deformable bodies and continuum
/// regions (scikit-fem imported from the running Python when a scene has them).
fn registry() -> Registry {
    let mut reg = nscdd_rigid_disks::registry();
    reg.add_plugin(&nscdd_spheres::SpheresPlugin);
    reg.add_plugin(&nscdd_polyhedra::PolyhedraPlugin);
    #[cfg(feature = "fem")]
    reg.add_plugin(&nscdd_fem_deformable::FemPlugin);
    reg
}

enum Inner {
    D2(Sim<D2>),
    D3(Sim<D3>),
}

/// `each!(inner, s => expr)`: expr with s the simulation of either dimension.
macro_rules! each {
    ($inner:expr, $s:ident => $e:expr) => {
        match $inner {
            Inner::D2($s) => $e,
            Inner::D3($s) => $e,
        }
    };
}

/// The simulation and a step's result moved through `Python::detach`.
struct Detached<'a>(&'a mut Inner);
struct Stepped(Result<Option<nscdd::engine::StepReport>, nscdd::run::RunError>);
// SAFETY: `Python::detach` runs its closure on the calling thread (it only
// releases the GIL), so nothing crosses threads; `Inner` holds no Python object
// (the fem plugin takes the GIL again with `Python::attach` where it calls Python).
// `Send` is asked only to keep GIL-bound references out of the closure.
unsafe impl Send for Detached<'_> {}
unsafe impl Send for Stepped {}

fn run_err(e: nscdd::run::RunError) -> PyErr {
    RunError::new_err(e.to_string())
}

/// A loaded scene and its run (docs/PYTHON.md).
///
/// Simulation(scene, out=None, restart=None): `scene` is a path to a TOML scene
/// file or a dict of the same keys; `out` a folder for the outputs `nscdd run`
/// writes (history.csv, VTK frames, checkpoints, final.json), None to write
/// nothing; `restart` a saved state (final.json or checkpoint.json) to continue.
#[pyclass(unsendable, module = "nscdd._nscdd")]
pub struct Simulation {
    inner: Inner,
    /// The registry the scene was loaded with (its plugins'), kept with it.
    _reg: Registry,
}

impl Simulation {
    fn load(text: &str, file: &str, out: Option<PathBuf>, restart: Option<PathBuf>) -> PyResult<Self> {
        let mut reg = registry();
        // the plugin libraries the scene names (`[[plugins]]`), before it is read
        nscdd::plugin::load_for_scene(text, file, &mut reg).map_err(|e| SceneError::new_err(e.to_string()))?;
        if let (Some(o), Some(state)) = (&out, &restart) {
            nscdd::scene::restart::check_out_dir(o, state).map_err(|m| SceneError::new_err(format!("out: {m}")))?;
        }
        let any = nscdd::scene::load_any_str(text, file, &reg).map_err(|e| SceneError::new_err(e.to_string()))?;
        let input = |e: nscdd::run::RunError| match e {
            nscdd::run::RunError::Param(_) | nscdd::run::RunError::Input(_) => SceneError::new_err(e.to_string()),
            e => run_err(e),
        };
        let inner = match any {
            AnyScene::D2(mut s) => {
                restarted(&mut s, restart.as_deref())?;
                Inner::D2(Sim::start(s, &reg, out).map_err(input)?)
            }
            AnyScene::D3(mut s) => {
                restarted(&mut s, restart.as_deref())?;
                Inner::D3(Sim::start(s, &reg, out).map_err(input)?)
            }
        };
        Ok(Simulation { inner, _reg: reg })
    }

    fn array<'py>(py: Python<'py>, (v, width): (Vec<f64>, usize)) -> PyResult<Bound<'py, PyAny>> {
        let n = v.len() / width.max(1);
        let a = PyArray1::from_vec(py, v);
        if width == 1 {
            Ok(a.into_any())
        } else {
            Ok(a.reshape([n, width])?.into_any())
        }
    }

    /// `n` steps with the GIL released.
    fn steps(&mut self, py: Python<'_>, n: u64) -> PyResult<Option<nscdd::engine::StepReport>> {
        let d = Detached(&mut self.inner);
        let res = py.detach(move || {
            let d = d;
            Stepped(each!(d.0, s => s.steps(n)))
        });
        res.0.map_err(run_err)
    }

    fn report<'py>(&self, py: Python<'py>, rep: &nscdd::engine::StepReport) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let (step, t) = each!(&self.inner, s => (s.scene.world.step, s.scene.world.t));
        d.set_item("step", step)?;
        d.set_item("time", t)?;
        d.set_item("contacts", rep.contacts)?;
        d.set_item("sweeps", rep.solve.sweeps)?;
        d.set_item("converged", rep.solve.converged)?;
        d.set_item("residual", rep.solve.residual)?;
        Ok(d)
    }
}

/// A read-only NumPy view of columns `cols` of the simulation's positions (or, with
/// `twist`, velocities), (n, cols.len()), keeping the simulation alive: it shows
/// the state after the last step, at every step.
fn view<'py>(slf: &Bound<'py, Simulation>, twist: bool, cols: std::ops::Range<usize>) -> PyResult<Bound<'py, PyAny>> {
    let (ptr, n, per) = each!(&slf.borrow().inner, s => s.raw(twist));
    assert!(cols.end <= per, "columns within a body's values");
    let shape = numpy::ndarray::ShapeBuilder::strides((n, cols.len()), (per, 1));
    // SAFETY: `ptr` points at n × per f64 owned by the simulation's world (its
    // bodies' array, made at load and never reallocated: `Sim::raw`), which the
    // view's base object (the simulation) keeps alive; the view is read-only, so
    // NumPy never writes through it. The values change at each step (a live view).
    let a = unsafe {
        let v = numpy::ndarray::ArrayView2::from_shape_ptr(shape, ptr.add(cols.start));
        numpy::PyArray2::<f64>::borrow_from_array(&v, slf.clone().into_any())
    };
    let kw = PyDict::new(slf.py());
    kw.set_item("write", false)?;
    a.call_method("setflags", (), Some(&kw))?;
    Ok(a.into_any())
}

/// Columns `cols` of the positions (`twist`: velocities): the live [`view`], or a
/// copy of it.
fn columns<'py>(slf: &Bound<'py, Simulation>, twist: bool, cols: std::ops::Range<usize>, copy: bool) -> PyResult<Bound<'py, PyAny>> {
    let v = view(slf, twist, cols)?;
    match copy {
        true => v.call_method0("copy"),
        false => Ok(v),
    }
}

/// A scene continued from a saved state.
fn restarted<D: nscdd::dim::Dim>(s: &mut nscdd::scene::Scene<D>, state: Option<&std::path::Path>) -> PyResult<()> {
    match state {
        Some(p) => nscdd::scene::restart_scene(s, p).map_err(|e| SceneError::new_err(e.to_string())),
        None => Ok(()),
    }
}

/// `run`'s steps up to step `end`: the GIL taken back at least every 10 steps
/// (signals, the bar) and at every `every`-th step for the callback. A callback
/// that steps the simulation itself moves the count on.
fn run_loop(
    slf: &Bound<'_, Simulation>,
    end: u64,
    callback: Option<&Bound<'_, PyAny>>,
    every: u64,
    bar: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let py = slf.py();
    loop {
        let now = slf.borrow().current_step();
        if now >= end {
            return Ok(());
        }
        let to_callback = every - now % every;
        let k = (end - now).min(10).min(if callback.is_some() { to_callback } else { u64::MAX });
        slf.borrow_mut().steps(py, k)?;
        if let Some(b) = bar {
            b.call_method1("update", (k,))?;
        }
        py.check_signals()?;
        let now = slf.borrow().current_step();
        if let Some(cb) = callback {
            if now % every == 0 || now >= end {
                cb.call1((slf,))?;
            }
        }
    }
}

fn summary_dict<'py>(py: Python<'py>, s: &nscdd::run::RunSummary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("steps", s.steps)?;
    d.set_item("total_sweeps", s.total_sweeps)?;
    d.set_item("unconverged_steps", s.unconverged_steps)?;
    d.set_item("first_unconverged", s.first_unconverged)?;
    d.set_item("suspect_steps", s.suspect_steps)?;
    d.set_item("max_residual", s.max_residual)?;
    d.set_item("wall_seconds", s.wall_seconds)?;
    Ok(d)
}

#[pymethods]
impl Simulation {
    #[new]
    #[pyo3(signature = (scene, out=None, restart=None))]
    fn new(scene: &Bound<'_, PyAny>, out: Option<PathBuf>, restart: Option<PathBuf>) -> PyResult<Self> {
        if let Ok(d) = scene.cast::<PyDict>() {
            let table = toml_of::table(d, "")?;
            let text = toml::to_string(&table).map_err(|e| SceneError::new_err(format!("the scene dict: {e}")))?;
            return Self::load(&text, "<scene dict>", out, restart);
        }
        let path: PathBuf = scene.extract()?;
        let text =
            std::fs::read_to_string(&path).map_err(|e| SceneError::new_err(format!("{}: cannot read the file: {e}", path.display())))?;
        Self::load(&text, &path.display().to_string(), out, restart)
    }

    /// A simulation from the text of a TOML scene.
    #[staticmethod]
    #[pyo3(signature = (text, out=None, restart=None))]
    fn from_toml(text: &str, out: Option<PathBuf>, restart: Option<PathBuf>) -> PyResult<Self> {
        Self::load(text, "<scene text>", out, restart)
    }

    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> usize {
        match self.inner {
            Inner::D2(_) => 2,
            Inner::D3(_) => 3,
        }
    }
    /// Steps done (a restart continues its count).
    #[getter]
    fn current_step(&self) -> u64 {
        each!(&self.inner, s => s.scene.world.step)
    }
    /// The scene's last step (`[time] steps`; moved by `run(n)` past it).
    #[getter]
    fn total_steps(&self) -> u64 {
        each!(&self.inner, s => s.scene.world.time.steps)
    }
    #[getter]
    fn time(&self) -> f64 {
        each!(&self.inner, s => s.scene.world.t)
    }
    #[getter]
    fn n_bodies(&self) -> usize {
        each!(&self.inner, s => s.scene.world.bodies.len())
    }
    /// The gravity vector (m/s²); settable between steps (rigid scenes).
    #[getter]
    fn gravity(&self) -> Vec<f64> {
        each!(&self.inner, s => s.scene.world.gravity.as_ref().to_vec())
    }
    #[setter]
    fn set_gravity(&mut self, g: Vec<f64>) -> PyResult<()> {
        each!(&mut self.inner, s => s.set_gravity(&g)).map_err(PyValueError::new_err)
    }
    /// Whether finish() was called (the run's outputs are closed).
    #[getter]
    fn finished(&self) -> bool {
        each!(&self.inner, s => s.run.finished())
    }

    /// One step; its report (step, time, contacts, sweeps, converged, residual).
    fn step<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let rep = self.steps(py, 1)?.expect("one step");
        self.report(py, &rep)
    }

    /// Runs `steps` more steps (default: to the scene's end, then finish()).
    /// `callback(sim)` after every `every` steps; a progress bar when `progress`
    /// and tqdm is installed. Ctrl-C stops after the current step, writing
    /// checkpoint.json (with an output folder), and raises KeyboardInterrupt.
    /// Returns the run's summary so far.
    #[pyo3(signature = (steps=None, *, callback=None, every=1, progress=true))]
    fn run<'py>(
        slf: &Bound<'py, Self>,
        steps: Option<u64>,
        callback: Option<Bound<'py, PyAny>>,
        every: u64,
        progress: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let end = match steps {
            Some(n) => slf.borrow().current_step() + n,
            None => slf.borrow().total_steps(),
        };
        let start = slf.borrow().current_step();
        let bar = match progress {
            true => py.import("tqdm").ok().map(|t| {
                let kw = PyDict::new(py);
                let _ = kw.set_item("total", end.saturating_sub(start));
                let _ = kw.set_item("unit", "step");
                t.call_method("tqdm", (), Some(&kw))
            }),
            false => None,
        }
        .transpose()?;
        let res = run_loop(slf, end, callback.as_ref(), every.max(1), bar.as_ref());
        if let Some(b) = &bar {
            let _ = b.call_method0("close");
        }
        if let Err(e) = res {
            // Ctrl-C (between steps, in the callback or the bar): the run's
            // checkpoint and series
            if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                if let Some(err) = each!(&mut slf.borrow_mut().inner, s => s.interrupt()) {
                    return Err(run_err(err));
                }
            }
            return Err(e);
        }
        let mut this = slf.borrow_mut();
        let sum = match steps {
            None => each!(&mut this.inner, s => s.finish()).map_err(run_err)?,
            Some(_) => each!(&this.inner, s => s.run.summary()),
        };
        summary_dict(py, &sum)
    }

    /// Ends the run: the VTK series and final.json written (with an output
    /// folder); its summary. No step after it.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let sum = each!(&mut self.inner, s => s.finish()).map_err(run_err)?;
        summary_dict(py, &sum)
    }

    /// Writes the state as a restart file (the format of final.json):
    /// `Simulation(scene, restart=path)` continues it bitwise.
    fn save(&mut self, path: PathBuf) -> PyResult<()> {
        each!(&mut self.inner, s => s.save(&path)).map_err(run_err)
    }

    /// Body positions, (n, dim): a copy, or with `copy=False` a read-only live
    /// view of the simulation's own array (docs/PYTHON.md).
    #[pyo3(signature = (copy=true))]
    fn positions<'py>(slf: &Bound<'py, Self>, copy: bool) -> PyResult<Bound<'py, PyAny>> {
        let dim = slf.borrow().dimension();
        columns(slf, false, 0..dim, copy)
    }
    /// Translational velocities, (n, dim); `copy=False`: a live view.
    #[pyo3(signature = (copy=true))]
    fn velocities<'py>(slf: &Bound<'py, Self>, copy: bool) -> PyResult<Bound<'py, PyAny>> {
        let dim = slf.borrow().dimension();
        columns(slf, true, 0..dim, copy)
    }
    /// Angular velocities: (n,) in 2D, (n, 3) in 3D; `copy=False`: a live view.
    #[pyo3(signature = (copy=true))]
    fn angular_velocities<'py>(slf: &Bound<'py, Self>, copy: bool) -> PyResult<Bound<'py, PyAny>> {
        let dim = slf.borrow().dimension();
        let w = columns(slf, true, dim..if dim == 2 { 3 } else { 6 }, copy)?;
        match dim {
            2 => w.call_method1("reshape", (-1,)),
            _ => Ok(w),
        }
    }
    /// Rotations: the angle (n,) in 2D, rotation vectors (n, 3) in 3D.
    fn rotations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Self::array(py, each!(&self.inner, s => s.rotations()))
    }
    /// Radii of balls (disks, spheres), the size of other shapes, (n,).
    fn radii<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Self::array(py, each!(&self.inner, s => s.radii()))
    }
    /// Each body's shape: `kinds` (the shape kinds' names: "disk", "wall",
    /// "sphere", "polyhedron"…), `kind` (n,) an index in them, `shape` (n,) the
    /// shape's id within its kind.
    fn shapes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (names, kind, shape) = each!(&self.inner, s => s.shapes());
        let d = PyDict::new(py);
        d.set_item("kinds", names)?;
        d.set_item("kind", PyArray1::from_vec(py, kind))?;
        d.set_item("shape", PyArray1::from_vec(py, shape))?;
        Ok(d)
    }
    /// Masses (2D: per unit depth), (n,).
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Self::array(py, each!(&self.inner, s => s.masses()))
    }
    /// Body names (None for unnamed bodies).
    fn names(&self) -> Vec<Option<String>> {
        each!(&self.inner, s => s.scene.world.names.clone())
    }
    /// The index of the body named `name`.
    fn body(&self, name: &str) -> PyResult<usize> {
        each!(&self.inner, s => s.body(name)).ok_or_else(|| PyValueError::new_err(format!("no body named `{name}`")))
    }

    /// The contacts of the last step as a dict of arrays: `bodies` (m, 2), `point`,
    /// `normal`, `r` (local impulse: normal first), `impulse` (world frame) (m, dim),
    /// `gap` (m,), `bonded` (m,).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let ((rec, width), dim) = (each!(&self.inner, s => s.contacts()), self.dimension());
        let n = rec.len() / width;
        let col = |a: usize, w: usize| -> Vec<f64> { (0..n).flat_map(|i| rec[i * width + a..i * width + a + w].to_vec()).collect() };
        let d = PyDict::new(py);
        let bodies: Vec<u32> = col(0, 2).into_iter().map(|x| x as u32).collect();
        d.set_item("bodies", PyArray1::from_vec(py, bodies).reshape([n, 2])?)?;
        for (i, name) in ["point", "normal", "r", "impulse"].iter().enumerate() {
            d.set_item(name, PyArray1::from_vec(py, col(3 + i * dim, dim)).reshape([n, dim])?)?;
        }
        d.set_item("gap", PyArray1::from_vec(py, col(3 + 4 * dim, 1)))?;
        d.set_item(
            "bonded",
            PyArray1::from_vec(py, col(4 + 4 * dim, 1).into_iter().map(|x| x != 0.0).collect::<Vec<bool>>()),
        )?;
        Ok(d)
    }

    /// With NSCDD (a `[decomposition]`), after a step: `bodies` (n,) the subdomain
    /// holding most of each body's contacts (−1: none), `copies` (n,) how many
    /// subdomains hold a copy of it, `contacts` (m,) each contact's subdomain.
    /// None without a decomposition or before the first step.
    fn subdomains<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some((b, m, c)) = each!(&self.inner, s => s.subdomains()) else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("bodies", PyArray1::from_vec(py, b))?;
        d.set_item("copies", PyArray1::from_vec(py, m))?;
        d.set_item("contacts", PyArray1::from_vec(py, c))?;
        Ok(Some(d))
    }

    /// The history (the columns of history.csv) as a dict of arrays, or with
    /// `as_frame` as a pandas DataFrame.
    #[pyo3(signature = (as_frame=false))]
    fn history<'py>(&mut self, py: Python<'py>, as_frame: bool) -> PyResult<Bound<'py, PyAny>> {
        let text = each!(&mut self.inner, s => s.history_text());
        let mut lines = text.lines();
        let cols: Vec<&str> = lines.next().map(|h| h.split(',').collect()).unwrap_or_default();
        let mut data: Vec<Vec<&str>> = vec![vec![]; cols.len()];
        for l in lines {
            for (c, x) in data.iter_mut().zip(l.split(',')) {
                c.push(x);
            }
        }
        // the counts as integers, the text of `prevailing` as text, the rest floats
        const COUNTS: [&str; 12] = [
            "step",
            "bodies",
            "contacts",
            "active",
            "sweeps",
            "converged",
            "nscdd_iterations",
            "interface_bodies",
            "links",
            "migrations",
            "subdomains",
            "repartitioned",
        ];
        let d = PyDict::new(py);
        for (c, v) in cols.into_iter().zip(data) {
            let ints = COUNTS
                .contains(&c)
                .then(|| v.iter().map(|x| x.parse::<i64>()).collect::<Result<Vec<_>, _>>());
            if let Some(Ok(ints)) = ints {
                d.set_item(c, PyArray1::from_vec(py, ints))?;
            } else if let Ok(fl) = v.iter().map(|x| x.parse::<f64>()).collect::<Result<Vec<_>, _>>() {
                d.set_item(c, PyArray1::from_vec(py, fl))?;
            } else {
                d.set_item(c, py.import("numpy")?.call_method1("array", (v,))?)?;
            }
        }
        if as_frame {
            return py.import("pandas")?.call_method1("DataFrame", (d,));
        }
        Ok(d.into_any())
    }

    /// Changes the drive of degree of freedom `dof` ("x", "y", "rot"; 3D "z",
    /// "rx", "ry", "rz") of a driven body (name or index) between steps; `drive`
    /// in the scene's syntax: {"velocity": -0.01}, {"force": 1e3},
    /// [{"force": -1e4, "until": 1.0}, {"velocity": -0.01}].
    fn set_drive(&mut self, body: &Bound<'_, PyAny>, dof: &str, drive: &Bound<'_, PyAny>) -> PyResult<()> {
        let k = match body.extract::<usize>() {
            Ok(k) => k,
            Err(_) => self.body(&body.extract::<String>()?)?,
        };
        let v = toml_of::value(drive, "drive")?;
        let d: nscdd::drive::DofDrive = v
            .try_into()
            .map_err(|e: toml::de::Error| PyValueError::new_err(format!("drive: {}", e.message())))?;
        each!(&mut self.inner, s => s.set_drive(k, dof, d)).map_err(PyValueError::new_err)
    }

    fn __repr__(&self) -> String {
        format!(
            "<nscdd.Simulation {}D, {} bodies, step {} of {}>",
            self.dimension(),
            self.n_bodies(),
            self.current_step(),
            self.total_steps()
        )
    }
}

#[pymodule]
fn _nscdd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(fc::_solve_fc_coo, m)?)?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
