//! Builtin procedural scenes, addressed as `builtin:NAME?key=value&...`.
//!
//! | name | stands in for (Lin et al. 2020, §4, Table 3) | default size |
//! |---|---|---:|
//! | [`hairball`] | Hairball (Laine's, 2.9M): thin curly tubes tangled in a sphere | 2.9M |
//! | [`forest`] | Vegetation (1.1M): trees with thin overlapping leaf cards, grass, ground | 1.1M |
//! | [`atrium`] | Crytek Sponza (262K): axis-aligned courtyard, two storeys of arches | 262K |
//! | [`cornell`] | a tiny Cornell box for tests | 34 |
//!
//! ## Spec grammar
//!
//! `NAME` optionally followed by `?` and `key=value` pairs joined by `&`, e.g.
//! `hairball?triangles=500000&seed=7`. Every scene documents its keys on its `*Params`
//! struct (each field is a key with a default). An unknown scene, an unknown or repeated key,
//! a malformed or out-of-range value is a typed [`SceneError::Builtin`], never a silent
//! default: this is a measurement tool.
//!
//! ## Determinism
//!
//! Every random choice comes from [`dualsplit_geometry::Pcg32`] seeded by `seed` and a
//! per-object stream id (strand, tree, …). Objects are generated in parallel with rayon into
//! fixed, precomputed slots of the output, so the same spec gives bit-identical triangles in
//! the same order on any machine and with any number of threads.
//!
//! ## Triangle budgets
//!
//! `triangles=N` is a target: each generator sizes its objects (strand count, tree count,
//! tile count) so the result lands within a few tenths of a percent of `N` for realistic
//! sizes and always within ±5 % above each scene's documented minimum.

pub mod atrium;
pub mod cornell;
pub mod forest;
pub mod hairball;
mod mesh;

pub use atrium::AtriumParams;
pub use cornell::CornellParams;
pub use forest::ForestParams;
pub use hairball::HairballParams;

use crate::{Limits, LoadStats, Scene, SceneError};
use std::str::FromStr;

/// Names of the builtin scenes, in documentation order.
pub const NAMES: [&str; 4] = ["hairball", "forest", "atrium", "cornell"];

/// Generates the builtin scene named by `spec` (the part after `builtin:`), with its default
/// camera and light.
///
/// ```
/// let scene = dualsplit_scene::builtin::generate("cornell").unwrap();
/// assert_eq!(scene.triangles.len(), 34);
/// assert!(dualsplit_scene::builtin::generate("teapot").is_err());
/// ```
pub fn generate(spec: &str) -> Result<Scene, SceneError> {
    generate_with(spec, &Limits::default())
}

/// [`generate`] within `limits`: a `triangles=N` target above
/// [`Limits::max_triangles`] is refused before anything is generated, and so is a result
/// that lands above it.
pub fn generate_with(spec: &str, limits: &Limits) -> Result<Scene, SceneError> {
    let mut p = Params::parse(spec)?;
    let name = p.name.clone();
    let what = format!("builtin:{spec}");
    let (triangles, camera, light) = match name.as_str() {
        "hairball" => {
            let s = HairballParams::from_params(&mut p)?;
            p.finish()?;
            limits.check_triangles(&what, u64::from(s.triangles))?;
            (s.triangles(), s.camera(), s.light())
        }
        "forest" => {
            let s = ForestParams::from_params(&mut p)?;
            p.finish()?;
            limits.check_triangles(&what, u64::from(s.triangles))?;
            (s.triangles(), s.camera(), s.light())
        }
        "atrium" => {
            let s = AtriumParams::from_params(&mut p)?;
            p.finish()?;
            limits.check_triangles(&what, u64::from(s.triangles))?;
            (s.triangles(), s.camera(), s.light())
        }
        "cornell" => {
            let s = CornellParams::from_params(&mut p)?;
            p.finish()?;
            (s.triangles(), s.camera(), s.light())
        }
        _ => {
            return Err(p.error(format!(
                "unknown builtin scene `{name}` (known: {})",
                NAMES.join(", ")
            )));
        }
    };
    limits.check_triangles(&what, triangles.len() as u64)?;
    let mut scene = Scene::from_triangles(name, what, triangles, LoadStats::default())?;
    scene.camera = camera;
    scene.light = light;
    Ok(scene)
}

/// The parsed `key=value` pairs of a spec. Generators take the keys they know with the typed
/// getters; [`Params::finish`] then rejects whatever is left.
#[derive(Clone, Debug)]
pub struct Params {
    spec: String,
    name: String,
    pairs: Vec<(String, String)>,
    used: Vec<bool>,
    known: Vec<&'static str>,
}

impl Params {
    /// Splits `NAME?k=v&k=v`. Errors on an empty name, a pair without `=`, an empty key or
    /// value, and a key given twice.
    pub fn parse(spec: &str) -> Result<Self, SceneError> {
        let (name, query) = match spec.split_once('?') {
            Some((n, q)) => (n, Some(q)),
            None => (spec, None),
        };
        let mut p = Self {
            spec: spec.to_string(),
            name: name.trim().to_string(),
            pairs: Vec::new(),
            used: Vec::new(),
            known: Vec::new(),
        };
        if p.name.is_empty() {
            return Err(p.error(format!("missing scene name (known: {})", NAMES.join(", "))));
        }
        for pair in query.unwrap_or("").split('&').filter(|s| !s.is_empty()) {
            let Some((k, v)) = pair.split_once('=') else {
                return Err(p.error(format!("`{pair}` is not of the form key=value")));
            };
            let (k, v) = (k.trim(), v.trim());
            if k.is_empty() || v.is_empty() {
                return Err(p.error(format!("`{pair}` has an empty key or value")));
            }
            if p.pairs.iter().any(|(pk, _)| pk == k) {
                return Err(p.error(format!("key `{k}` is given twice")));
            }
            p.pairs.push((k.to_string(), v.to_string()));
            p.used.push(false);
        }
        Ok(p)
    }

    /// The scene name (before `?`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A [`SceneError::Builtin`] for this spec.
    pub fn error(&self, message: String) -> SceneError {
        SceneError::Builtin {
            spec: self.spec.clone(),
            message,
        }
    }

    /// The value of `key` parsed as `T` and checked to lie in `[min, max]`, or `default`
    /// when the key is absent.
    pub fn get<T>(&mut self, key: &'static str, default: T, min: T, max: T) -> Result<T, SceneError>
    where
        T: FromStr + PartialOrd + Copy + std::fmt::Display,
    {
        self.known.push(key);
        let Some(i) = self.pairs.iter().position(|(k, _)| k == key) else {
            return Ok(default);
        };
        self.used[i] = true;
        let raw = &self.pairs[i].1;
        let v: T = raw.parse().map_err(|_| {
            self.error(format!(
                "`{key}={raw}`: not a valid {}",
                std::any::type_name::<T>()
            ))
        })?;
        // `!(a <= b)` also rejects NaN.
        if !(min <= v && v <= max) {
            return Err(self.error(format!(
                "`{key}={raw}` is out of range: must lie in [{min}, {max}]"
            )));
        }
        Ok(v)
    }

    /// Rejects every key no getter asked for.
    pub fn finish(&self) -> Result<(), SceneError> {
        if let Some(i) = self.used.iter().position(|u| !u) {
            let mut known = self.known.clone();
            known.sort_unstable();
            known.dedup();
            return Err(self.error(format!(
                "unknown key `{}` for `{}` (known: {})",
                self.pairs[i].0,
                self.name,
                known.join(", ")
            )));
        }
        Ok(())
    }
}
