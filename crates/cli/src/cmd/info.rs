//! `dualsplit info SCENE [--json]`: loads a scene (file or `builtin:` spec) and prints its
//! name, triangle counts, bounds, the degenerate/non-finite counts of the crate-wide rule
//! (see `dualsplit_scene`), polygons triangulated, skipped glTF primitives, and the load
//! time. The load time is a host wall-clock measurement, reported for information only.
//!
//! JSON schema (`--json`), one object:
//! `{"name", "spec", "triangles", "source_triangles", "degenerate", "non_finite",
//! "polygons_triangulated", "primitives_skipped", "bounds": {"min": [x,y,z], "max": [x,y,z]},
//! "load_ms"}`.
use crate::progress::Ctx;
use std::process::ExitCode;

/// Arguments of `dualsplit info`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// Print one JSON object instead of a table; `--json=FILE` writes it to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<std::path::PathBuf>,
}

/// What `info` reports, also its JSON form.
#[derive(serde::Serialize)]
struct Info<'a> {
    name: &'a str,
    spec: &'a str,
    triangles: u64,
    source_triangles: u64,
    degenerate: u64,
    non_finite: u64,
    polygons_triangulated: u64,
    primitives_skipped: u64,
    bounds: &'a dualsplit_geometry::Aabb,
    load_ms: f64,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let json = crate::output::JsonOut::from_arg(args.json.as_deref())?;
    let spinner = ctx.spinner(format!("loading {}", args.scene));
    let start = std::time::Instant::now();
    let scene = dualsplit_scene::load_with(&args.scene, &ctx.limits);
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    spinner.finish_and_clear();
    // The error names the file (and line) or the builtin spec already.
    let scene = scene?;
    let s = &scene.stats;
    let info = Info {
        name: &scene.name,
        spec: &scene.spec,
        triangles: scene.triangles.len() as u64,
        source_triangles: s.source_triangles,
        degenerate: s.degenerate,
        non_finite: s.non_finite,
        polygons_triangulated: s.polygons_triangulated,
        primitives_skipped: s.primitives_skipped,
        bounds: &scene.bounds,
        load_ms,
    };
    if let Some(out) = json {
        out.emit(&serde_json::to_string_pretty(&info)?)?;
    } else {
        out!("{}", table(&info));
    }
    Ok(ExitCode::SUCCESS)
}

/// The human-readable form.
fn table(i: &Info<'_>) -> String {
    let v = |p: dualsplit_geometry::Vec3| format!("({}, {}, {})", p.x, p.y, p.z);
    let rows = [
        ("name", i.name.to_string()),
        ("spec", i.spec.to_string()),
        ("triangles", group(i.triangles)),
        ("source triangles", group(i.source_triangles)),
        ("degenerate (kept)", group(i.degenerate)),
        ("non-finite (dropped)", group(i.non_finite)),
        ("polygons triangulated", group(i.polygons_triangulated)),
        ("primitives skipped", group(i.primitives_skipped)),
        ("bounds min", v(i.bounds.min)),
        ("bounds max", v(i.bounds.max)),
        ("extent", v(i.bounds.max - i.bounds.min)),
        ("load time", format!("{:.0} ms", i.load_ms)),
    ];
    rows.iter().map(|(k, v)| format!("{k:<22} {v}\n")).collect()
}

/// `1234567` → `1,234,567`.
fn group(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (k, c) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{Args, group, run};
    use crate::progress::Ctx;

    fn info(scene: &str) -> anyhow::Result<std::process::ExitCode> {
        let args = Args {
            scene: scene.into(),
            json: Some("-".into()),
        };
        run(args, &Ctx::new(true))
    }

    #[test]
    fn bad_scenes_are_errors_naming_the_file() {
        let e = info("no/such/mesh.stl").unwrap_err().to_string();
        assert!(
            e.contains("no/such/mesh.stl") && e.contains("unknown scene format"),
            "{e}"
        );
        let e = info("no/such/mesh.ply").unwrap_err().to_string();
        assert!(e.contains("no/such/mesh.ply"), "{e}");
        let dir = std::env::temp_dir().join(format!("dualsplit-info-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.obj");
        std::fs::write(&bad, "v 0 0 0\nf 1 2 3\n").unwrap();
        let e = info(bad.to_str().unwrap()).unwrap_err().to_string();
        assert!(e.contains("bad.obj:2:"), "{e}");
        let good = dir.join("good.obj");
        std::fs::write(&good, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert!(info(good.to_str().unwrap()).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn grouping() {
        assert_eq!(group(0), "0");
        assert_eq!(group(999), "999");
        assert_eq!(group(1000), "1,000");
        assert_eq!(group(6_166_352), "6,166,352");
    }
}
