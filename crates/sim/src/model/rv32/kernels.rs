//! The compiled ray-tracing kernels (`kernels/`, built by `make -C kernels`) and the parameter
//! block they read (`docs/isa.md`).
//!
//! One ELF per configuration and workload, `kernels/build/<config>-<workload>.elf`, committed
//! so that building needs only Rust; [`elf`] hands out the bytes. [`Params`] is the Rust
//! mirror of `struct Params` in `kernels/dualsplit.h`, the block at [`PARAMS_ADDR`] that tells
//! a thread everything about the frame: resolution, samples, seed, the camera and light
//! constants the renderer derives from the scene ([`FrameConstants`]), and where the memory
//! image's regions are.

use crate::accel::SimAccel;
use crate::config::KernelsConfig;
use crate::model::rv32::placement::Placement;
pub use crate::model::rv32::{FRAME_BUFFER_ADDR, LOCAL_STORE_ADDR, PARAMS_ADDR};
use crate::model::rv32::{PROGRAM_BASE, Program};
use dualsplit_accel::{MemoryImage, TraversalSet};
use dualsplit_render::{FrameConstants, RenderSettings, Workload};
use dualsplit_scene::Scene;

/// Bytes of a thread's local store (`LOCAL_STORE_BYTES` in `kernels/dualsplit.h`): the
/// deepest traversal stack (256 BVH entries of 8 B or 192 DST entries of 12 B) and the
/// renderer's frames.
pub const LOCAL_STORE_BYTES: u32 = 4096;
/// Floats per pixel in the frame buffer (the kernels write the grey radiance three times).
pub const FRAME_FLOATS_PER_PIXEL: usize = 3;

/// The parameter block (`struct Params`, `kernels/dualsplit.h`), field for field. Word
/// ranges count 32-bit words from image address 0.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Params {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the per-pixel hash.
    pub seed: u32,
    /// 0 cast, 1 path (each kernel is built for one).
    pub workload: u32,
    /// Diffuse bounces after the primary hit.
    pub bounces: u32,
    /// Camera eye.
    pub eye: [f32; 3],
    /// Camera forward axis.
    pub fwd: [f32; 3],
    /// Camera right axis.
    pub right: [f32; 3],
    /// Camera up axis.
    pub up: [f32; 3],
    /// `tan(fov_y / 2)`.
    pub tan_half_fov: f32,
    /// Light centre.
    pub light_pos: [f32; 3],
    /// Light radius.
    pub light_radius: f32,
    /// Light power.
    pub light_power: f32,
    /// Self-intersection offset.
    pub eps: f32,
    /// First word of the node region.
    pub nodes_start: u32,
    /// End of the node region.
    pub nodes_end: u32,
    /// First word of the triangle-index region.
    pub indices_start: u32,
    /// End of the triangle-index region.
    pub indices_end: u32,
    /// First word of the triangle region.
    pub triangles_start: u32,
    /// End of the triangle region.
    pub triangles_end: u32,
    /// Word of the root node.
    pub root: u32,
    /// The DST's scene box, lower corner.
    pub scene_min: [f32; 3],
    /// The DST's scene box, upper corner.
    pub scene_max: [f32; 3],
    /// Byte address of the frame buffer.
    pub frame_buffer: u32,
    /// 1: a shadow ray at every hit; 0: none, the light sample counted as visible.
    pub shadows: u32,
}

const _: () = assert!(size_of::<Params>() == 160);

impl Params {
    /// The block for rendering `scene` with `settings` on configuration `accel` (whose
    /// memory image is `structures.image(accel.kind())`).
    pub fn new<S: TraversalSet>(
        scene: &Scene,
        structures: &S,
        accel: SimAccel,
        settings: &RenderSettings,
    ) -> Params {
        let fc = FrameConstants::new(scene);
        let img = structures.image(accel.kind());
        let scene_box = structures.scene_box();
        let word = |w: usize| u32::try_from(w).expect("image word index fits 32 bits");
        Params {
            width: settings.width,
            height: settings.height,
            spp: settings.spp,
            seed: settings.seed,
            workload: match settings.workload {
                Workload::Cast => 0,
                Workload::Path => 1,
            },
            bounces: settings.bounces,
            eye: fc.eye.to_array(),
            fwd: fc.fwd.to_array(),
            right: fc.right.to_array(),
            up: fc.up.to_array(),
            tan_half_fov: fc.tan_half_fov,
            light_pos: scene.light.position.to_array(),
            light_radius: scene.light.radius,
            light_power: fc.light_power,
            eps: fc.eps,
            nodes_start: word(img.nodes.start),
            nodes_end: word(img.nodes.end),
            indices_start: word(img.indices.start),
            indices_end: word(img.indices.end),
            triangles_start: word(img.triangles.start),
            triangles_end: word(img.triangles.end),
            root: 0,
            scene_min: scene_box.min.to_array(),
            scene_max: scene_box.max.to_array(),
            frame_buffer: FRAME_BUFFER_ADDR,
            shadows: u32::from(settings.shadows),
        }
    }

    /// The block's bytes, as the kernels read them at [`PARAMS_ADDR`].
    pub fn as_bytes(&self) -> &[u8] {
        bytemuck::bytes_of(self)
    }

    /// Bytes of the frame buffer of these settings.
    pub fn frame_bytes(&self) -> usize {
        self.width as usize * self.height as usize * FRAME_FLOATS_PER_PIXEL * 4
    }
}

/// Where a frame's regions lie in the caches and DRAM (`memory::placement`): the parameter
/// block, the program `prog`, the memory `image`, then the frame buffer, from line
/// boundaries of `line_bytes`.
pub fn placement(
    params: &Params,
    prog: &Program,
    image: &MemoryImage,
    line_bytes: u64,
) -> Placement {
    let program_bytes = (prog.data_base() - PROGRAM_BASE) as u64 + prog.bytes().len() as u64;
    Placement::new(
        params.as_bytes().len() as u64,
        program_bytes,
        image.triangles.end as u64 * 4,
        line_bytes,
    )
}

/// The file name of a kernel: `<config>-<workload><variant>.elf` (variant suffix `""`,
/// `-parity`, `-loads`, `-parity-loads` or `-parity-loads-sortall`,
/// [`KernelsConfig::suffix`]), as `kernels/Makefile` names it.
pub fn elf_name(accel: SimAccel, workload: Workload, variant: KernelsConfig) -> String {
    format!(
        "{}-{}{}.elf",
        accel.name(),
        workload.name(),
        variant.suffix()
    )
}

/// The compiled kernel of configuration `accel`, `workload` and `variant` (an RV32IMF ELF).
pub fn elf(accel: SimAccel, workload: Workload, variant: KernelsConfig) -> &'static [u8] {
    accel.kernel(workload == Workload::Path, variant)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_geometry::EXIT_WIDEN;

    fn kernels_file(name: &str) -> String {
        let p = format!("{}/../../kernels/{name}", env!("CARGO_MANIFEST_DIR"));
        std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
    }

    /// The table above holds exactly the ELFs the Makefile builds, in the right slots.
    #[test]
    fn the_elf_table_is_the_makefiles() {
        let dir = format!("{}/../../kernels/build", env!("CARGO_MANIFEST_DIR"));
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.ends_with(".elf"))
            .collect();
        on_disk.sort();
        let mut ours = Vec::new();
        for a in SimAccel::ALL {
            for w in Workload::ALL {
                for v in KernelsConfig::ALL {
                    let name = elf_name(a, w, v);
                    let bytes = std::fs::read(format!("{dir}/{name}")).unwrap();
                    assert_eq!(elf(a, w, v), &bytes[..], "{name}");
                    ours.push(name);
                }
            }
        }
        ours.sort();
        assert_eq!(on_disk, ours);
        let mk = kernels_file("Makefile");
        assert!(mk.contains("CONFIGS := bvh2 bvh2+ bvh4 bvh4+ bvh8 bvh8+ dst-sw dst"));
        assert!(mk.contains("WORKLOADS := cast path"));
        assert!(mk.contains("VARIANTS := base parity loads parity-loads parity-loads-sortall"));
    }

    /// The C header spells the constants the Rust side uses.
    #[test]
    fn the_header_agrees() {
        let h = kernels_file("dualsplit.h");
        // EXIT_WIDEN lies in [1, 2): exponent 0, so the hex float is 0x1.<mantissa << 1>p+0.
        let frac = (EXIT_WIDEN.to_bits() & 0x7F_FFFF) << 1;
        assert!(
            h.contains(&format!("#define EXIT_WIDEN 0x1.{frac:06x}p+0f")),
            "EXIT_WIDEN"
        );
        assert!(h.contains(&format!("sizeof(struct Params) == {}", size_of::<Params>())));
        assert!(h.contains(&format!("#define PARAMS_ADDR {PARAMS_ADDR:#010x}u")));
        assert!(h.contains(&format!("#define LOCAL_STORE_BYTES {LOCAL_STORE_BYTES}")));
    }
}
