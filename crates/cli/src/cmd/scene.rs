//! `dualsplit scene`: scene files made from public meshes.
//!
//! `dualsplit scene dragon-box DRAGON -o dragon_box.ply.gz` builds the reconstructed Dragon Box
//! from the Stanford dragon exactly as the shipped `dragon_box.ply.gz` was made
//! ([`dualsplit_scene::make`]): the dragon's triangles in file order, then an open box
//! of 10 triangles. DRAGON is any scene file (the Stanford `dragon_vrip.ply`, or the
//! shipped `dragon.ply.gz`); the output is a gzipped binary little-endian PLY.
//!
//! `dualsplit scene convert IN -o OUT.ply.gz` writes any scene file's triangles in the
//! same format (`scripts/get-scenes.sh` converts the downloaded originals with it).
//!
//! Both print `triangles sha256 HEX`: [`dualsplit_scene::make::triangles_sha256`], the
//! checksum of the triangles themselves, which does not depend on the file's encoding.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_scene::make;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The scene files `dualsplit scene` makes.
#[derive(clap::Subcommand)]
pub enum Command {
    /// The reconstructed Dragon Box from the Stanford dragon: the dragon, then an axis-aligned
    /// cube (side 1.5 × the dragon's largest extent) open on +z, the dragon on its floor.
    DragonBox(DragonBoxArgs),
    /// Any scene file (.obj, .ply, .gltf, .glb, optionally .gz) as a gzipped binary PLY of
    /// its triangles, in the loader's triangle order (vertices with equal bits written once).
    Convert(ConvertArgs),
}

/// Arguments of `dualsplit scene convert`.
#[derive(clap::Args)]
pub struct ConvertArgs {
    /// The scene to convert.
    #[arg(value_parser = crate::args::parse_scene)]
    input: String,
    /// The file to write (gzipped binary PLY).
    #[arg(short, long)]
    output: PathBuf,
}

/// Arguments of `dualsplit scene dragon-box`.
#[derive(clap::Args)]
pub struct DragonBoxArgs {
    /// The dragon: a scene file (.ply, .obj, optionally .gz, .gltf, .glb).
    #[arg(value_parser = crate::args::parse_scene)]
    dragon: String,
    /// The Dragon Box file to write (gzipped binary PLY).
    #[arg(short, long)]
    output: PathBuf,
    /// Close the box behind the camera (10 more triangles: the walls carried on past the
    /// open side to a front wall behind the preset camera). Name the file
    /// `dragon_box_closed.ply.gz`: that stem gets the open box's camera and light.
    #[arg(long)]
    closed: bool,
}

/// Runs the subcommand.
pub fn run(cmd: Command, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    match cmd {
        Command::DragonBox(args) => {
            crate::output::check_file(&args.output, "-o")?;
            crate::output::check_not_an_input(&args.output, "-o", &[Path::new(&args.dragon)])?;
            let dragon = super::load(&args.dragon, ctx)?;
            let tris = if args.closed {
                make::closed_dragon_box(&dragon.triangles)
            } else {
                make::dragon_box(&dragon.triangles)
            };
            let n = dragon.triangles.len();
            make::check_dragon_box(&dragon.spec, n, &tris)?;
            let comments = [
                format!(
                    "Dragon Box: {} ({n} tris, faces 0..{})",
                    dragon.name,
                    n.saturating_sub(1)
                ),
                if args.closed {
                    "plus an open-front (+z) box of 10 triangles, then 10 closing it behind the \
                     camera, appended as the last faces"
                } else {
                    "plus an open-front (+z) box of 10 triangles appended as the last faces"
                }
                .to_string(),
                "made by dualsplit scene dragon-box".to_string(),
            ];
            let comments: Vec<&str> = comments.iter().map(String::as_str).collect();
            make::write_ply_gz(&args.output, &tris, &comments)
                .with_context(|| format!("writing {}", args.output.display()))?;
            outln!(
                "wrote {}: {} triangles ({n} of {}, {} of the box), triangles sha256 {}",
                args.output.display(),
                tris.len(),
                dragon.spec,
                tris.len() - n,
                make::triangles_sha256(&tris)
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Convert(args) => {
            crate::output::check_file(&args.output, "-o")?;
            crate::output::check_not_an_input(&args.output, "-o", &[Path::new(&args.input)])?;
            let scene = super::load(&args.input, ctx)?;
            let comment = format!(
                "{} ({} tris) converted by dualsplit scene convert",
                scene.name,
                scene.triangles.len()
            );
            make::write_ply_gz(&args.output, &scene.triangles, &[&comment])
                .with_context(|| format!("writing {}", args.output.display()))?;
            outln!(
                "wrote {}: {} triangles of {}, triangles sha256 {}",
                args.output.display(),
                scene.triangles.len(),
                scene.spec,
                make::triangles_sha256(&scene.triangles)
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}
