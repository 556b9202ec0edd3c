//! Argument parsers and argument groups shared by the subcommands: structure, workload and
//! resolution names, scene specs (checked before any work starts), and the camera and light
//! overrides of `render` and `simulate`.
use anyhow::Context;
use dualsplit_accel::AccelKind;
use dualsplit_render::Workload;
use dualsplit_scene::Scene;
use dualsplit_sim::SimAccel;
use std::path::Path;

/// Parses a structure name.
pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    AccelKind::parse(s).ok_or_else(|| {
        format!(
            "unknown structure `{s}` (expected one of {})",
            AccelKind::names()
        )
    })
}

/// A value parser that takes the names of a registry: `parse` reads one, and `--help`
/// lists `names` as the flag's possible values, so help, parser and registry cannot
/// disagree.
#[derive(Clone)]
pub struct Names<T: Clone + Send + Sync + 'static> {
    parse: fn(&str) -> Result<T, String>,
    names: fn() -> Vec<&'static str>,
}

impl<T: Clone + Send + Sync + 'static> Names<T> {
    /// The parser of one registry's names.
    pub fn new(parse: fn(&str) -> Result<T, String>, names: fn() -> Vec<&'static str>) -> Self {
        Self { parse, names }
    }
}

impl<T: Clone + Send + Sync + 'static> clap::builder::TypedValueParser for Names<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        clap::builder::TypedValueParser::parse_ref(&self.parse, cmd, arg, value)
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(
            (self.names)()
                .into_iter()
                .map(clap::builder::PossibleValue::new),
        ))
    }
}

/// `--accel` of the commands that trace one traversal: [`AccelKind`]'s names.
pub fn accel_names() -> Names<AccelKind> {
    Names::new(parse_accel, || AccelKind::ALL.map(AccelKind::name).to_vec())
}

/// `--accel` of the commands that simulate: [`SimAccel`]'s names and `all`.
pub fn sim_accel_names() -> Names<SimAccelArg> {
    Names::new(parse_sim_accel, || {
        let mut names: Vec<&str> = SimAccel::ALL.iter().map(|a| a.name()).collect();
        names.push("all");
        names
    })
}

/// One item of `simulate --accel`: a configuration, or `all` of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimAccelArg {
    /// Every configuration, in the paper's order.
    All,
    /// One configuration.
    One(SimAccel),
}

/// Parses a simulated configuration name or `all`.
pub fn parse_sim_accel(s: &str) -> Result<SimAccelArg, String> {
    if s == "all" {
        return Ok(SimAccelArg::All);
    }
    SimAccel::parse(s).map(SimAccelArg::One).ok_or_else(|| {
        format!(
            "unknown configuration `{s}` (expected one of {} or all)",
            SimAccel::names()
        )
    })
}

/// The configurations a `--accel` list names, in the order given, each once (`all` expands
/// to every configuration in the paper's order).
pub fn sim_accels(items: &[SimAccelArg]) -> Vec<SimAccel> {
    let mut out = Vec::new();
    for item in items {
        let add: &[SimAccel] = match item {
            SimAccelArg::All => &SimAccel::ALL,
            SimAccelArg::One(a) => std::slice::from_ref(a),
        };
        for a in add {
            if !out.contains(a) {
                out.push(*a);
            }
        }
    }
    out
}

/// Parses a workload name.
pub fn parse_workload(s: &str) -> Result<Workload, String> {
    Workload::parse(s).ok_or_else(|| format!("unknown workload `{s}` (expected cast or path)"))
}

/// Parses `WxH` or `N` (for N×N), both positive.
pub fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let num = |t: &str| {
        t.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("bad resolution `{s}` (expected WIDTHxHEIGHT or N, positive)"))
    };
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((num(w)?, num(h)?)),
        None => num(s).map(|n| (n, n)),
    }
}

/// Parses a positive count (TMs, resolution side).
pub fn parse_positive(s: &str) -> Result<u32, String> {
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("`{s}` is not a positive whole number"))
}

/// What a scene argument is, for the help texts.
pub const SCENE_HELP: &str = "a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params (hairball, forest, atrium, cornell)";

/// Checks a scene spec before anything is loaded: a `builtin:` spec passes (its name and
/// parameters are checked when it is generated); a file must exist and not be a directory.
/// The message for a missing file says so and names the builtins, suggesting `builtin:NAME`
/// when the spec is a builtin's bare name.
pub fn parse_scene(spec: &str) -> Result<String, String> {
    if spec.starts_with("builtin:") {
        return Ok(spec.to_string());
    }
    let path = Path::new(spec);
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(format!("`{spec}` is a directory; a scene is {SCENE_HELP}")),
        Ok(_) => Ok(spec.to_string()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let names = dualsplit_scene::builtin::NAMES;
            let name = spec.split('?').next().unwrap_or(spec);
            let hint = if names.contains(&name) {
                format!(" (did you mean builtin:{spec}?)")
            } else {
                String::new()
            };
            Err(format!(
                "no such file: `{spec}`{hint}; a scene is a file (.obj, .ply, .gltf, .glb, optionally .gz) or a generated builtin: {}",
                names
                    .iter()
                    .map(|n| format!("builtin:{n}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        }
        Err(e) => Err(format!("`{spec}`: {e}")),
    }
}

/// Checks an `x,y,z` vector's syntax; the value is kept as text for the scene's
/// `with_overrides`.
fn parse_vec3_text(s: &str) -> Result<String, String> {
    dualsplit_scene::parse_vec3("value", s)
        .map(|_| s.to_string())
        .map_err(|e| e.to_string())
}

/// Camera and light overrides, as `render` and `simulate` take them.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct View {
    /// Camera position x,y,z (default: the scene's camera).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3_text)]
    pub eye: Option<String>,
    /// Point the camera looks at, x,y,z.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3_text)]
    pub target: Option<String>,
    /// Vertical field of view in degrees, in (0, 180).
    #[arg(long)]
    pub fov: Option<f32>,
    /// Light centre x,y,z (default: the scene's light).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3_text)]
    pub light: Option<String>,
    /// Light radius (0 = point light, hard shadows).
    #[arg(long)]
    pub light_radius: Option<f32>,
}

impl View {
    /// Applies the overrides to `scene`'s camera and light.
    pub fn apply(&self, scene: &mut Scene) -> anyhow::Result<()> {
        scene.camera = scene
            .camera
            .with_overrides(self.eye.as_deref(), self.target.as_deref(), self.fov)
            .context("camera options")?;
        scene.light = scene
            .light
            .with_overrides(self.light.as_deref(), self.light_radius, None)
            .context("light options")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolutions() {
        assert_eq!(parse_res("64"), Ok((64, 64)));
        assert_eq!(parse_res("64x32"), Ok((64, 32)));
        assert!(parse_res("0").is_err());
        assert!(parse_res("64x").is_err());
    }

    #[test]
    fn sim_accel_lists_keep_order_and_drop_repeats() {
        let (a, b) = (SimAccel::ALL[SimAccel::ALL.len() - 1], SimAccel::ALL[0]);
        let items = [a.name(), b.name(), "all"].map(|s| parse_sim_accel(s).unwrap());
        let got = sim_accels(&items);
        assert_eq!(got.len(), SimAccel::ALL.len());
        assert_eq!(&got[..2], &[a, b]);
        assert!(parse_sim_accel("bvh3").is_err());
    }

    #[test]
    fn missing_scene_files_are_named() {
        let e = parse_scene("no/such/scene.obj").unwrap_err();
        assert!(e.contains("no such file"), "{e}");
        assert!(e.contains("builtin:hairball"), "{e}");
        let e = parse_scene("forest").unwrap_err();
        assert!(e.contains("did you mean builtin:forest?"), "{e}");
        assert!(parse_scene("builtin:anything").is_ok());
    }
}

/// The scope of a study, shared by `report` and `plan`: scenes, frame size, TM counts and
/// thread model.
#[derive(clap::Args, Clone, Debug)]
pub struct Scope {
    /// Scenes: files (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell). Without any: the Dragon Box (`dragon_box.ply.gz`:
    /// SimTRaX's scene, or the reconstruction, as its bounds tell) when the scenes folder holds it, and the atrium, forest and hairball builtins at reduced
    /// sizes.
    #[arg(value_name = "SCENES", value_parser = crate::args::parse_scene)]
    pub specs: Vec<String>,
    /// Square resolution of the simulated frames (default 384, 1024 with --full).
    #[arg(long, value_parser = crate::args::parse_positive)]
    pub res: Option<u32>,
    /// The paper's setup: 1024×1024 (the resolution it states for Table 4; it states none
    /// for the other tables), full-size scenes, 32/64/128 TMs.
    #[arg(long)]
    pub full: bool,
    /// Folder of the shipped meshes (Dragon Box, Dragon Sponza). Default: the
    /// DUALSPLIT_SCENES environment variable, else shared/scenes beside the checkout.
    #[arg(long = "scenes", value_name = "DIR")]
    pub scenes_dir: Option<std::path::PathBuf>,
    /// TM counts of the scaling study (Table 7); Tables 4–6 use 64 when listed.
    #[arg(long, value_delimiter = ',', default_value = "32,64,128", value_parser = crate::args::parse_positive)]
    pub tms: Vec<u32>,
    /// Thread model: rv32 (the compiled kernels instruction by instruction, the reference)
    /// or fast (the replay calibrated against them: about 5× faster, frame times within 13 %), or simt
    /// (an RTX-style GPU; with --config configs/rtx2060.toml, whose simt.* keys --vary
    /// sweeps). Default: fast, rv32 with --full.
    #[arg(long)]
    pub model: Option<String>,
}

/// Host threads for simulations, shared by `simulate`, `report`, `run-job` and `plan`.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct SimThreads {
    /// Host threads the simulations run on in all (default: this host's cores). Frames
    /// run side by side first; a frame's TMs are split over several threads when there are
    /// fewer frames than threads. Results are bit-identical for any number.
    #[arg(long = "sim-threads", value_name = "N", value_parser = parse_positive)]
    pub sim_threads: Option<u32>,
}

impl SimThreads {
    /// The number asked for, else the host's cores.
    pub fn get(self) -> usize {
        self.sim_threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, usize::from),
            |n| n as usize,
        )
    }
}
