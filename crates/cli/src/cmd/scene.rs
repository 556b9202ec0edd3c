//! `dualsplit scene`: scene files made from public meshes.
//!
//! `dualsplit scene dragon-box DRAGON -o dragon_box.ply.gz` builds the paper's Dragon Box as
//! SimTRaX ships it ([`dualsplit_scene::make::dragon_box`]): the dragon's triangles in file
//! order, then SimTRaX's closed box of 12 triangles; DRAGON is the Stanford dragon in its
//! original coordinates (the Stanford `dragon_vrip.ply`, the shipped `dragon.ply.gz` or one
//! of its decimations). Named `dragon_box.ply.gz`, it gets SimTRaX's camera and light.
//! `--reconstruction` builds the box this project reconstructed before SimTRaX's scene was
//! used (an open box fitted to any mesh; name it `dragon_box_recon.ply.gz`), `--closed`
//! closes that one behind its camera (`dragon_box_recon_closed.ply.gz`). The output is a
//! gzipped binary little-endian PLY.
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
    /// The paper's Dragon Box as SimTRaX ships it (samples/scenes/dragon, commit f2537ff):
    /// the Stanford dragon in its original coordinates, then SimTRaX's closed 12-triangle
    /// box. `--reconstruction`: this project's earlier reconstruction instead.
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
    /// Make the reconstruction instead of SimTRaX's scene: the dragon, then an axis-aligned
    /// cube (side 1.5 × the mesh's largest extent) open on +z, the mesh on its floor. Name
    /// the file `dragon_box_recon.ply.gz` for its camera and light.
    #[arg(long)]
    reconstruction: bool,
    /// With `--reconstruction`: close the box behind the camera (10 more triangles: the
    /// walls carried on past the open side to a front wall behind the preset camera). Name
    /// the file `dragon_box_recon_closed.ply.gz`: that stem gets the open box's camera and
    /// light.
    #[arg(long, requires = "reconstruction")]
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
                make::closed_reconstructed_dragon_box(&dragon.triangles)
            } else if args.reconstruction {
                make::reconstructed_dragon_box(&dragon.triangles)
            } else {
                make::check_inside_simtrax_box(&dragon.spec, &dragon.triangles)?;
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
                    "plus a reconstructed open-front (+z) box of 10 triangles, then 10 closing \
                     it behind the camera, appended as the last faces"
                } else if args.reconstruction {
                    "plus a reconstructed open-front (+z) box of 10 triangles appended as the \
                     last faces"
                } else {
                    "plus SimTRaX's closed box of 12 triangles (samples/scenes/dragon/\
                     dragon_box.obj, commit f2537ff) appended as the last faces"
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
