//! The Python module `dualsplit._dualsplit`, re-exported by the `dualsplit` package: scenes
//! with their triangles as NumPy arrays, the structures (build, save, load), batched ray
//! queries on the Rust thread pool, and the simulator returning `simulate --json`'s
//! document. Every Rust error becomes a `dualsplit.DualsplitError` carrying its message
//! (with its causes, as the command line prints them); no panic crosses into Python.
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, Structures, TraversalSet, TreeKind,
};
use dualsplit_geometry::{Ray, Triangle, Vec3};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_report::simulate::{SimulateJson, check_frame, simulate_frames};
use dualsplit_report::study::vary;
use dualsplit_sim::{SimAccel, SimConfig, SimResult, ThreadModel};
use numpy::{
    PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use rayon::prelude::*;
use std::path::PathBuf;

pyo3::create_exception!(
    _dualsplit,
    DualsplitError,
    pyo3::exceptions::PyException,
    "An error reported by dualsplit's Rust code; the message is the Rust error's, with its causes."
);

/// `err` and its causes, `outer: inner: ...`, as the command line prints an error.
fn message(err: &(dyn std::error::Error + 'static)) -> String {
    let mut out = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !out.ends_with(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
        cause = c.source();
    }
    out
}

/// A `DualsplitError` for `err`, prefixed with `context` when given.
fn py_err(context: &str, err: &(dyn std::error::Error + 'static)) -> PyErr {
    if context.is_empty() {
        DualsplitError::new_err(message(err))
    } else {
        DualsplitError::new_err(format!("{context}: {}", message(err)))
    }
}

/// A path or a string as text. A name that is not valid UTF-8 (a `str` with surrogate
/// escapes, an `os.PathLike` of such bytes) is a `DualsplitError`: scene specs are text,
/// and a lossy conversion would silently name another file.
fn path_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    let not_utf8 = |name: String| {
        DualsplitError::new_err(format!(
            "path {name} is not valid UTF-8; scene files must have UTF-8 names"
        ))
    };
    if let Ok(s) = obj.cast::<PyString>() {
        return match s.to_cow() {
            Ok(t) => Ok(t.into_owned()),
            Err(_) => Err(not_utf8(
                s.repr().map(|r| r.to_string()).unwrap_or_default(),
            )),
        };
    }
    let p: PathBuf = obj.extract().map_err(|_| {
        PyTypeError::new_err("expected a str or an os.PathLike naming a file or builtin:NAME")
    })?;
    match p.to_str() {
        Some(t) => Ok(t.to_owned()),
        None => Err(not_utf8(format!("{p:?}"))),
    }
}

/// A loaded scene: its triangles as a read-only `(N, 3, 3)` float32 array (triangle,
/// vertex, xyz) that owns the loader's memory (no copy), its bounds, camera and light.
#[pyclass(module = "dualsplit", frozen)]
struct Scene {
    /// The scene without its triangles (they live in `triangles`).
    meta: dualsplit_scene::Scene,
    /// The triangles, `(N, 3, 3)` float32, read-only.
    triangles: Py<PyArray3<f32>>,
}

impl Scene {
    fn new(py: Python<'_>, mut scene: dualsplit_scene::Scene) -> PyResult<Self> {
        let tris = std::mem::take(&mut scene.triangles);
        let n = tris.len();
        // Triangle is 9 packed f32s (Pod): the Vec's memory becomes the array's.
        let flat: Vec<f32> = bytemuck::allocation::try_cast_vec(tris)
            .unwrap_or_else(|(_, tris)| bytemuck::cast_slice(&tris).to_vec());
        // An owned ndarray moves into the NumPy array without a copy.
        let shaped = numpy::ndarray::Array3::from_shape_vec((n, 3, 3), flat)
            .map_err(|e| DualsplitError::new_err(format!("triangle array: {e}")))?;
        let arr = PyArray3::from_owned_array(py, shaped);
        let kwargs = PyDict::new(py);
        kwargs.set_item("write", false)?;
        arr.call_method("setflags", (), Some(&kwargs))?;
        Ok(Self {
            meta: scene,
            triangles: arr.unbind(),
        })
    }

    /// The triangles, copied out of the array.
    fn triangle_vec(&self, py: Python<'_>) -> PyResult<Vec<Triangle>> {
        let arr = self.triangles.bind(py).readonly();
        let flat = arr.as_slice()?;
        Ok(bytemuck::cast_slice::<f32, Triangle>(flat).to_vec())
    }

    /// The whole scene, triangles included (a copy), for the renderer and simulator.
    fn full(&self, py: Python<'_>) -> PyResult<dualsplit_scene::Scene> {
        let mut s = self.meta.clone();
        s.triangles = self.triangle_vec(py)?;
        Ok(s)
    }
}

#[pymethods]
impl Scene {
    /// Short name: the file stem or the builtin's name.
    #[getter]
    fn name(&self) -> &str {
        &self.meta.name
    }

    /// The spec the scene was loaded from.
    #[getter]
    fn spec(&self) -> &str {
        &self.meta.spec
    }

    /// The triangles, a read-only `(N, 3, 3)` float32 array; a triangle's id (`prim`) is its
    /// row.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        self.triangles.bind(py).clone()
    }

    /// The bounds as `(min, max)`, two float32 arrays of 3.
    #[getter]
    fn bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f32>>, Bound<'py, PyArray1<f32>>) {
        let b = &self.meta.bounds;
        (
            PyArray1::from_slice(py, &b.min.to_array()),
            PyArray1::from_slice(py, &b.max.to_array()),
        )
    }

    /// The default camera, as `simulate`'s JSON gives it.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.meta.camera)
    }

    /// The default light, as `simulate`'s JSON gives it.
    #[getter]
    fn light<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.meta.light)
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.triangles.bind(py).shape()[0]
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<dualsplit.Scene {} ({} triangles)>",
            self.meta.name,
            self.__len__(py)
        )
    }
}

/// `value` serialized to JSON and parsed by Python's `json` module.
fn json_to_py<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| py_err("to JSON", &e))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Loads a scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or `builtin:NAME?params`.
#[pyfunction]
#[pyo3(signature = (spec, *, max_triangles=None, max_bytes=None))]
fn load_scene(
    py: Python<'_>,
    spec: &Bound<'_, PyAny>,
    max_triangles: Option<u64>,
    max_bytes: Option<u64>,
) -> PyResult<Scene> {
    let spec = path_text(spec)?;
    let mut limits = dualsplit_scene::Limits::default();
    if let Some(n) = max_triangles {
        limits.max_triangles = n;
    }
    if let Some(n) = max_bytes {
        limits.max_bytes = n;
    }
    let scene = py
        .detach(|| dualsplit_scene::load_with(&spec, &limits))
        .map_err(|e| py_err(&format!("loading scene {spec}"), &e))?;
    Scene::new(py, scene)
}

/// A `Scene` object, or a spec loaded with the default limits.
fn scene_arg(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Py<Scene>> {
    if let Ok(s) = obj.cast::<Scene>() {
        return Ok(s.clone().unbind());
    }
    let s = load_scene(py, obj, None, None)?;
    Py::new(py, s)
}

/// One structure: a BVH2, BVH4, BVH8, DST, CWBVH or DST-Q, built or loaded from a saved
/// tree file.
#[pyclass(module = "dualsplit", frozen)]
struct Tree {
    tree: AnyTree,
    scene: Py<Scene>,
}

fn parse_tree_kind(s: &str) -> PyResult<TreeKind> {
    TreeKind::parse(s).ok_or_else(|| {
        PyValueError::new_err(format!("unknown structure `{s}` ({})", TreeKind::names()))
    })
}

/// Builds one structure of `scene` (a scene or a spec) exactly as `dualsplit build` does:
/// `kind` is one of `STRUCTURES` (default: the dual-split tree, hardware preset), derived
/// from the scene's BVH2 (default build settings).
#[pyfunction]
#[pyo3(signature = (scene, kind=None))]
fn build(py: Python<'_>, scene: &Bound<'_, PyAny>, kind: Option<&str>) -> PyResult<Tree> {
    let kind = match kind {
        Some(k) => parse_tree_kind(k)?,
        None => TreeKind::DEFAULT,
    };
    let scene = scene_arg(py, scene)?;
    let tris = scene.get().triangle_vec(py)?;
    let spec = scene.get().meta.spec.clone();
    let tree = py
        .detach(|| -> Result<AnyTree, dualsplit_accel::AccelError> {
            let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default())?;
            AnyTree::derive(&bvh2, kind).unwrap_or_else(|| Ok(bvh2.into_tree().into()))
        })
        .map_err(|e| py_err(&format!("building the {kind} of {spec}"), &e))?;
    Ok(Tree { tree, scene })
}

/// A float32 scalar or an array of `n`, as one value per ray.
enum PerRay<'py> {
    One(f32),
    Each(PyReadonlyArray1<'py, f32>),
}

impl PerRay<'_> {
    fn get(&self, i: usize) -> f32 {
        match self {
            PerRay::One(v) => *v,
            PerRay::Each(a) => a.as_array()[i],
        }
    }
}

fn per_ray<'py>(name: &str, obj: &Bound<'py, PyAny>, n: usize) -> PyResult<PerRay<'py>> {
    if let Ok(v) = obj.extract::<f32>() {
        return Ok(PerRay::One(v));
    }
    let arr: PyReadonlyArray1<'py, f32> = obj.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{name}: expected a float or a 1-D float32 array of {n} values"
        ))
    })?;
    if arr.as_array().len() != n {
        return Err(PyValueError::new_err(format!(
            "{name}: {} values for {n} rays",
            arr.as_array().len()
        )));
    }
    Ok(PerRay::Each(arr))
}

fn vec3_rows<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let arr: PyReadonlyArray2<'py, f32> = obj
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{name}: expected an (N, 3) float32 array")))?;
    if arr.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an (N, 3) float32 array, got shape {:?}",
            arr.shape()
        )));
    }
    Ok(arr)
}

/// The rays of `(origins, directions, tmin, tmax)`.
fn rays(
    origins: &Bound<'_, PyAny>,
    directions: &Bound<'_, PyAny>,
    tmin: Option<&Bound<'_, PyAny>>,
    tmax: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<Ray>> {
    let o = vec3_rows("origins", origins)?;
    let d = vec3_rows("directions", directions)?;
    let n = o.shape()[0];
    if d.shape()[0] != n {
        return Err(PyValueError::new_err(format!(
            "{n} origins but {} directions",
            d.shape()[0]
        )));
    }
    let lo = match tmin {
        Some(v) => per_ray("tmin", v, n)?,
        None => PerRay::One(0.0),
    };
    let hi = match tmax {
        Some(v) => per_ray("tmax", v, n)?,
        None => PerRay::One(f32::INFINITY),
    };
    let (o, d) = (o.as_array(), d.as_array());
    // Rays outside `Ray::is_traceable` are refused by index and field, as `dualsplit trace
    // --rays` refuses them, rather than answered with the traversals' defined miss.
    (0..n)
        .map(|i| {
            let ray = Ray {
                origin: Vec3::new(o[[i, 0]], o[[i, 1]], o[[i, 2]]),
                dir: Vec3::new(d[[i, 0]], d[[i, 1]], d[[i, 2]]),
                t_min: lo.get(i),
                t_max: hi.get(i),
            };
            dualsplit_accel::ray_file::check_ray(i as u64, &ray)
                .map(|()| ray)
                .map_err(|e| py_err("", &e))
        })
        .collect()
}

impl Tree {
    fn traversal(&self, name: Option<&str>) -> PyResult<AccelKind> {
        let kinds = self.tree.kind().accel_kinds();
        match name {
            None => Ok(kinds[0]),
            Some(s) => AccelKind::parse(s)
                .filter(|k| kinds.contains(k))
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "traversal `{s}`: a {} has {}",
                        self.tree.kind(),
                        self.tree.kind_names()
                    ))
                }),
        }
    }
}

type Hits<'py> = (
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<f32>>,
);

#[pymethods]
impl Tree {
    /// The structure's name, one of `STRUCTURES`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.tree.kind().name()
    }

    /// The traversals this structure has: `["dst-sw", "dst"]` for a DST, its own kind for a
    /// BVH.
    #[getter]
    fn traversals(&self) -> Vec<&'static str> {
        self.tree
            .kind()
            .accel_kinds()
            .iter()
            .map(|k| k.name())
            .collect()
    }

    /// The scene the structure was built from or checked against.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// Sizes, node counts and build time, as `dualsplit build --json`'s `stats`.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, self.tree.stats())
    }

    /// Saves the structure to a tree file (the format of `dualsplit build -o`).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.tree.save(&path))
            .map_err(|e| py_err("", &e))
    }

    /// Loads a tree file saved by `Tree.save` or `dualsplit build`; it must come from
    /// `scene` (its triangles are checked bit for bit).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf, scene: &Bound<'_, PyAny>) -> PyResult<Tree> {
        let scene = scene_arg(py, scene)?;
        let arr = scene.get().triangles.bind(py).readonly();
        let tris: &[Triangle] = bytemuck::cast_slice(arr.as_slice()?);
        let spec = scene.get().meta.spec.clone();
        let tree = py
            .detach(|| AnyTree::load(&path, Some(tris)))
            .map_err(|e| py_err(&format!("tree {} with scene {spec}", path.display()), &e))?;
        drop(arr);
        Ok(Tree { tree, scene })
    }

    /// Closest hits: `(t, prim, u, v)` arrays of N (float32, int64, float32, float32);
    /// a miss is `t = inf`, `prim = -1`, `u = v = 0`. Rays are `origins[i] + t *
    /// directions[i]` with `tmin <= t <= tmax` (scalars or arrays of N). A ray with a
    /// non-finite origin or direction, or a NaN `tmin` or `tmax`, is a `DualsplitError`
    /// naming the ray and the field (`tmax = inf` is the usual unbounded ray). Runs on the
    /// Rust thread pool without the GIL. `traversal` picks `dst-sw` or `dst` for a DST.
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, traversal=None))]
    fn intersect<'py>(
        &self,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        traversal: Option<&str>,
    ) -> PyResult<Hits<'py>> {
        let py = origins.py();
        let kind = self.traversal(traversal)?;
        let rays = rays(origins, directions, tmin, tmax)?;
        let hits = py.detach(|| {
            rays.par_iter()
                .map_init(|| self.tree.tracer(kind), |t, r| t.closest_hit(r))
                .collect::<Vec<_>>()
        });
        let n = hits.len();
        let (mut t, mut prim, mut u, mut v) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for h in hits {
            match h {
                Some(h) => {
                    t.push(h.t);
                    prim.push(i64::from(h.prim.0));
                    u.push(h.u);
                    v.push(h.v);
                }
                None => {
                    t.push(f32::INFINITY);
                    prim.push(-1);
                    u.push(0.0);
                    v.push(0.0);
                }
            }
        }
        Ok((
            PyArray1::from_vec(py, t),
            PyArray1::from_vec(py, prim),
            PyArray1::from_vec(py, u),
            PyArray1::from_vec(py, v),
        ))
    }

    /// Shadow rays: a bool array of N, true where the ray hits any triangle within
    /// `[tmin, tmax]`; rays are checked as in `intersect`. Runs on the Rust thread pool
    /// without the GIL.
    #[pyo3(signature = (origins, directions, tmin=None, tmax=None, *, traversal=None))]
    fn occluded<'py>(
        &self,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        traversal: Option<&str>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let py = origins.py();
        let kind = self.traversal(traversal)?;
        let rays = rays(origins, directions, tmin, tmax)?;
        let out = py.detach(|| {
            rays.par_iter()
                .map_init(|| self.tree.tracer(kind), |t, r| t.any_hit(r))
                .collect::<Vec<bool>>()
        });
        Ok(PyArray1::from_vec(py, out))
    }

    fn __repr__(&self) -> String {
        format!(
            "<dualsplit.Tree {} of {}>",
            self.tree.kind(),
            self.scene.get().meta.name
        )
    }
}

/// The configurations `accel` names (a name, `all`, or a list of them), each once in the
/// order given; `None` is `dst`, or every configuration of `tree`.
fn sim_accels(accel: Option<&Bound<'_, PyAny>>, tree: Option<&AnyTree>) -> PyResult<Vec<SimAccel>> {
    let names: Vec<String> = match accel {
        None => Vec::new(),
        Some(a) if a.cast::<PyString>().is_ok() => vec![a.extract()?],
        Some(a) => a.extract().map_err(|_| {
            PyTypeError::new_err("accel: expected a configuration name or a list of them")
        })?,
    };
    let supports = |a: SimAccel| tree.is_none_or(|t| t.supports(a.kind()));
    if names.is_empty() {
        return Ok(match tree {
            None => vec![SimAccel::DEFAULT],
            Some(_) => SimAccel::ALL.into_iter().filter(|a| supports(*a)).collect(),
        });
    }
    let mut out = Vec::new();
    for name in &names {
        let add: Vec<SimAccel> = if name == "all" {
            SimAccel::ALL.into_iter().filter(|a| supports(*a)).collect()
        } else {
            let a = SimAccel::parse(name).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "unknown configuration `{name}` (expected one of {} or all)",
                    SimAccel::names()
                ))
            })?;
            if let Some(t) = tree.filter(|t| !t.supports(a.kind())) {
                return Err(DualsplitError::new_err(format!(
                    "accel {name}: the tree holds a {}, whose traversals are {}",
                    t.kind(),
                    t.kind_names()
                )));
            }
            vec![a]
        };
        for a in add {
            if !out.contains(&a) {
                out.push(a);
            }
        }
    }
    Ok(out)
}

/// A Python value as a TOML value.
fn toml_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = v.cast::<pyo3::types::PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    Err(PyTypeError::new_err(format!(
        "config[{key:?}]: expected a bool, int, float or str"
    )))
}

/// Most levels of nested dicts in a `config` (the configuration's tables are one level
/// deep); deeper nesting, a dict that contains itself included, is a `DualsplitError`.
const MAX_CONFIG_DEPTH: usize = 4;

/// `config` flattened to dotted keys: `{"l2.size_bytes": 1}` and `{"l2": {"size_bytes": 1}}`
/// are the same. The recursion stops at [`MAX_CONFIG_DEPTH`] levels.
fn flatten(
    prefix: &str,
    depth: usize,
    map: &Bound<'_, PyDict>,
    out: &mut Vec<(String, toml::Value)>,
) -> PyResult<()> {
    if depth > MAX_CONFIG_DEPTH {
        return Err(DualsplitError::new_err(format!(
            "config[{prefix:?}]: nested more than {MAX_CONFIG_DEPTH} levels deep (a dict that contains itself?)"
        )));
    }
    for (k, v) in map.iter() {
        let k: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err("config keys must be str"))?;
        let key = if prefix.is_empty() {
            k
        } else {
            format!("{prefix}.{k}")
        };
        match v.cast::<PyDict>() {
            Ok(d) => flatten(&key, depth + 1, d, out)?,
            Err(_) => {
                let value = toml_value(&key, &v)?;
                out.push((key, value));
            }
        }
    }
    Ok(())
}

fn parse_res(res: &Bound<'_, PyAny>) -> PyResult<(u32, u32)> {
    let bad = || PyValueError::new_err("res: expected N or (WIDTH, HEIGHT), positive");
    let (w, h) = if let Ok(n) = res.extract::<u32>() {
        (n, n)
    } else {
        res.extract::<(u32, u32)>().map_err(|_| bad())?
    };
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// Largest configuration file read, as the command line's `--config`: 1 MiB.
const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The text of a configuration file: a regular file of at most [`MAX_CONFIG_BYTES`]
/// ([`dualsplit_scene::load::read_limited`], as the command line reads it).
fn read_config(p: &std::path::Path) -> PyResult<String> {
    let bytes =
        dualsplit_scene::load::read_limited(p, MAX_CONFIG_BYTES).map_err(|e| py_err("", &e))?;
    String::from_utf8(bytes)
        .map_err(|_| DualsplitError::new_err(format!("{}: not UTF-8 text", p.display())))
}

/// Simulates one frame per configuration on the TRaX-style many-core model (or, with
/// `model="simt"` and a `[simt]` chip, the RTX-style GPU model) and returns the document
/// `dualsplit simulate --json` prints, as a dict.
#[pyfunction]
#[pyo3(signature = (scene, *, accel=None, workload="path", res=None, tms=None, model="rv32", config=None, config_file=None, tree=None, threads=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    accel: Option<&Bound<'py, PyAny>>,
    workload: &str,
    res: Option<&Bound<'py, PyAny>>,
    tms: Option<u32>,
    model: &str,
    config: Option<&Bound<'py, PyDict>>,
    config_file: Option<PathBuf>,
    tree: Option<&Bound<'py, Tree>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    if threads == Some(0) {
        return Err(PyValueError::new_err(
            "threads: `0` is not a positive whole number",
        ));
    }
    let threads =
        threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from));
    let workload = Workload::parse(workload).ok_or_else(|| {
        PyValueError::new_err(format!(
            "unknown workload `{workload}` (expected cast or path)"
        ))
    })?;
    let model = ThreadModel::parse(model).ok_or_else(|| {
        PyValueError::new_err(format!(
            "unknown thread model `{model}` (expected rv32, fast or simt)"
        ))
    })?;
    let (w, h) = match res {
        Some(r) => parse_res(r)?,
        None => (512, 512),
    };
    if tms == Some(0) {
        return Err(PyValueError::new_err(
            "tms: `0` is not a positive whole number",
        ));
    }
    let mut cfg = match &config_file {
        Some(p) => {
            let text = read_config(p)?;
            SimConfig::from_toml(&text).map_err(|e| py_err(&format!("in {}", p.display()), &e))?
        }
        None => SimConfig::lin2020(),
    };
    if let Some(map) = config {
        let mut set = Vec::new();
        flatten("", 1, map, &mut set)?;
        cfg = vary::apply(&cfg, &set).map_err(|e| py_err("config", &e))?;
    }
    if let Some(t) = tms {
        cfg.tms = t;
    }
    let settings = RenderSettings::new(w, h, workload);
    check_frame(&cfg, &settings, model).map_err(|e| py_err("", &e))?;
    let scene = scene_arg(py, scene)?;
    let full = scene.get().full(py)?;
    if let Some(t) = tree
        && !t.get().scene.is(&scene)
    {
        let tt = t.get().scene.get().triangle_vec(py)?;
        if tt != full.triangles {
            return Err(DualsplitError::new_err(format!(
                "the tree was built from {}, not from {}",
                t.get().scene.get().meta.spec,
                full.spec
            )));
        }
    }
    let accels = sim_accels(accel, tree.map(|t| &t.get().tree))?;
    let results: Vec<(SimResult, std::time::Duration)> = match tree {
        Some(t) => {
            let t = &t.get().tree;
            py.detach(|| {
                simulate_frames(
                    model,
                    &full,
                    t,
                    &accels,
                    &settings,
                    &cfg,
                    threads,
                    &|_, _, _| {},
                )
            })
            .map_err(|e| py_err("", &e))?
        }
        None => py
            .detach(|| {
                let s = Structures::try_build(&full.triangles, &BuildConfig::default()).map_err(
                    |e| format!("building the structures of {}: {}", full.spec, message(&e)),
                )?;
                simulate_frames(
                    model,
                    &full,
                    &s,
                    &accels,
                    &settings,
                    &cfg,
                    threads,
                    &|_, _, _| {},
                )
                .map_err(|e| message(&e))
            })
            .map_err(DualsplitError::new_err)?,
    };
    let plain: Vec<&SimResult> = results.iter().map(|(r, _)| r).collect();
    let doc = SimulateJson::new(&full, &settings, model, &cfg, plain);
    json_to_py(py, &doc)
}

/// The names of the generated builtin scenes (`builtin:NAME`).
#[pyfunction]
fn builtins() -> Vec<&'static str> {
    dualsplit_scene::builtin::NAMES.to_vec()
}

/// The extension module.
#[pymodule]
fn _dualsplit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DualsplitError", m.py().get_type::<DualsplitError>())?;
    m.add_class::<Scene>()?;
    m.add_class::<Tree>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(build, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(builtins, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The registries' names: structures (`build`), traversals (`Tree.traversals`) and
    // simulated configurations (`simulate`).
    m.add("STRUCTURES", TreeKind::ALL.map(TreeKind::name).to_vec())?;
    m.add("TRAVERSALS", AccelKind::ALL.map(AccelKind::name).to_vec())?;
    m.add("CONFIGURATIONS", SimAccel::ALL.map(SimAccel::name).to_vec())?;
    Ok(())
}
