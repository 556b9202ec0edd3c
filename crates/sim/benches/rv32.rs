//! Functional speed of the RV32 interpreter (`crates/sim/src/rv32`): instructions per host
//! second on one core. `cargo bench -p dualsplit-sim --bench rv32`.
//!
//! `int_loop`: a counted loop of integer instructions (`addi`, `add`, `xor`, `slli`, `bne`).
//! `kernel_frame`: a compiled kernel (`kernels/build`) rendering a 32×32 path-traced frame
//! of `builtin:cornell` on one hart, BVH2 and DST: real code (floats, loads, stack, the
//! ray-tracing instructions), counted in instructions.
//!
//! Wall-clock throughput on the shared 2-core host varies with load; a deterministic
//! measure is callgrind/cachegrind's host instructions per simulated instruction:
//! `valgrind --tool=cachegrind --cache-sim=no <bench binary> --bench kernel_frame::Dst
//! --sample-count 1 --sample-size 1`, then the `run_counting` lines of `cg_annotate` divided by
//! the simulated instructions (two frames: the count run and one sample). At commit 26bcb2c:
//! 90 host instructions per simulated instruction for either kernel (4.88 M simulated
//! instructions per DST frame, 5.41 M per BVH2 frame); divan pinned to one core of a quiet
//! host: int_loop 131–198 M instructions/s, kernel_frame 81–132 M/s (BVH2) and 116–146 M/s
//! (DST), median–fastest (`docs/performance.md`, "What bounds it").

use divan::counter::ItemsCount;
use dualsplit_accel::{MemoryImage, Structures};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::SimAccel;
use dualsplit_sim::model::rv32::kernels::{LOCAL_STORE_BYTES, Params, elf};
use dualsplit_sim::model::rv32::{FrameMemory, Hart, Program, run_counting};

fn main() {
    divan::main();
}

const ITERS: u32 = 100_000;

/// The loop: x1 = ITERS; loop { x6 += 1; x3 += x6; x4 ^= x3; x5 = x4 << 1; bne x6, x1 }
fn int_loop() -> Program {
    let lui = |rd: u32, imm: u32| (imm & 0xFFFF_F000) | (rd << 7) | 0x37;
    let itype = |f3: u32, rd: u32, rs1: u32, imm: i32| {
        ((imm as u32 & 0xFFF) << 20) | (rs1 << 15) | (f3 << 12) | (rd << 7) | 0x13
    };
    let rtype = |f7: u32, f3: u32, rd: u32, rs1: u32, rs2: u32| {
        (f7 << 25) | (rs2 << 20) | (rs1 << 15) | (f3 << 12) | (rd << 7) | 0x33
    };
    let bne = |rs1: u32, rs2: u32, off: i32| {
        let o = off as u32;
        (((o >> 12) & 1) << 31)
            | (((o >> 5) & 0x3F) << 25)
            | (rs2 << 20)
            | (rs1 << 15)
            | (1 << 12)
            | (((o >> 1) & 0xF) << 8)
            | (((o >> 11) & 1) << 7)
            | 0x63
    };
    let hi = (ITERS + 0x800) & 0xFFFF_F000;
    let lo = ITERS.wrapping_sub(hi) as i32;
    Program::from_words(
        0x8000_0000,
        &[
            lui(1, hi),
            itype(0, 1, 1, lo),
            itype(0, 6, 6, 1),
            rtype(0, 0, 3, 3, 6),
            rtype(0, 4, 4, 4, 3),
            itype(1, 5, 4, 1),
            bne(6, 1, -16),
            0x0010_0073,
        ],
    )
}

#[divan::bench]
fn int_loop_instructions(bencher: divan::Bencher) {
    let prog = int_loop();
    let image = MemoryImage::default();
    let n = 2 + 5 * ITERS as u64 + 1;
    let mut hart = Hart::new(&prog, 4096);
    let mut mem = FrameMemory::new(&image, &[], 0);
    assert_eq!(
        run_counting(&mut hart, &prog, &mut mem, u64::MAX).unwrap(),
        n
    );
    assert_eq!(hart.x[6], ITERS);
    bencher.counter(ItemsCount::new(n)).bench_local(|| {
        hart.reset(&prog);
        run_counting(&mut hart, &prog, &mut mem, u64::MAX).unwrap()
    });
}

#[divan::bench(args = [SimAccel::Bvh2, SimAccel::Dst])]
fn kernel_frame(bencher: divan::Bencher, accel: SimAccel) {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let structures = Structures::build(&scene.triangles, &Default::default());
    let settings = RenderSettings::new(32, 32, Workload::Path);
    let prog = Program::from_elf(elf(accel, settings.workload, Default::default())).unwrap();
    let params = Params::new(&scene, &structures, accel, &settings);
    let image = structures.image(accel.kind());
    let run = || {
        let mut mem = FrameMemory::new(image, params.as_bytes(), params.frame_bytes());
        let mut hart = Hart::new(&prog, LOCAL_STORE_BYTES);
        run_counting(&mut hart, &prog, &mut mem, u64::MAX).unwrap()
    };
    let n = run();
    bencher.counter(ItemsCount::new(n)).bench_local(run);
}
