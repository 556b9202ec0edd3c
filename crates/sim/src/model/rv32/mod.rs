//! The thread processor's instruction set: RV32IMF plus the ray-tracing instructions of
//! `docs/isa.md` (the contract with the C kernels in `kernels/`), executed functionally.
//!
//! # API
//!
//! ```text
//! Program::from_elf(&[u8]) -> Result<Program, ElfError>     load + validate + pre-decode
//! Program::from_words(base, &[u32]) -> Program               hand-assembled snippets
//! FrameMemory::new(&MemoryImage, params: &[u8], frame_bytes) the global memory of a frame
//!     .frame: Vec<u8>, .frame_f32(), .globals: [u32; 8]
//! Hart::new(&Program, local_store_bytes) -> Hart             pc = entry, sp = local top
//! Hart::step(&mut self, &Program, &mut impl Memory) -> Result<Retired, ExecError>
//! run_to_halt(&mut Hart, &Program, &mut impl Memory, max_steps) -> Result<RunStats, RunError>
//! run_frame(&Program, &MemoryImage, params, frame_bytes, local_store_bytes, max_steps)
//!     -> Result<(Vec<u8> /* frame buffer */, RunStats), RunError>
//! decode(u32) -> Result<Instr, DecodeError>
//! ```
//!
//! Running a kernel over a frame functionally (one thread takes every pixel through
//! `rt.atominc` until they run out, then `ebreak`s):
//!
//! ```no_run
//! use dualsplit_sim::model::rv32::{Program, run_frame};
//! # fn params_bytes() -> Vec<u8> { vec![0; 160] }
//! # let image = dualsplit_accel::MemoryImage::default();
//! let prog = Program::from_elf(&std::fs::read("kernels/build/dst-cast.elf").unwrap()).unwrap();
//! let params = params_bytes(); // kernels::Params::new(..).as_bytes() (kernels/dualsplit.h)
//! let (w, h) = (64, 64);
//! let (frame, stats) = run_frame(&prog, &image, &params, w * h * 12, 4096, u64::MAX).unwrap();
//! let rgb: Vec<f32> = frame.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
//! println!("{} instructions", stats.instructions);
//! ```
//!
//! A timing model drives [`Hart::step`] itself: each call executes one instruction and
//! returns a [`Retired`] (16 bytes, `Copy`): its [`FuClass`], the registers it read
//! ([`Info::src`], int/float distinguished by [`Reg`], `x0` omitted), the register it wrote
//! ([`Info::dst`]), the latches it touched ([`Latches`]: ray registers `R`, box latch `B`,
//! DST latch `D`), its memory access ([`MemAccess`]: byte address, word count, load/store,
//! local store or global) and whether it was a taken branch. The static part ([`Info`]) is
//! also available before execution from [`Program::fetch`]`(pc).info`, so an issue stage
//! can check its scoreboard first and execute at issue, as SimTRaX does.
//!
//! # The thread processor
//!
//! - **Registers**: `x0..x31` (32-bit), `f0..f31` (f32 bits), `pc`; per `docs/isa.md` the
//!   ray register set `R` ([`Hart::ray`], a [`dualsplit_geometry::RayPre`] whose `origin`,
//!   `inv_dir`/`neg`, `k`, `shear` are `R`), the box latch `B[8]` and the DST latch `D`.
//! - **Base ISA**: RV32I, M, F. No compressed instructions, A, D, or `ecall` (decode
//!   errors). `fence` is a no-op. CSRs `fflags`, `frm`, `fcsr` read as 0; writing a
//!   rounding mode other than RNE is an error. `ebreak` halts the thread.
//! - **Floating point**: round-to-nearest-even only (arithmetic with a static `rm` other
//!   than 0 or 7 does not decode; `fcvt.w[u].s` honour every static mode, since C casts
//!   use `rtz`). NaN results of arithmetic are the canonical NaN `0x7FC00000`; `fmin`/`fmax`
//!   follow the F spec v2.2 (one NaN operand ignored, −0 < +0); `fcvt.w[u].s` saturate and
//!   map NaN to the maximum; `feq`/`flt`/`fle` are 0 on NaN; fused multiply-adds round once
//!   (`f32::mul_add`); `fdiv`/`fsqrt` are correctly rounded. `fflags` are not modelled.
//! - **Ray-tracing instructions** (custom-0 `0x0B`, custom-1 `0x2B`): `rt.setorg`,
//!   `rt.setinv`, `rt.setshear`, `rt.setk`, `rt.rcp`, `rt.atominc`, `rt.box`, `rt.boxn`,
//!   `rt.boxget`, `rt.tri`, `rt.dst`, `rt.dstget`; bit for bit the Rust functions
//!   `RayPre::slab`, `Triangle::intersect` and `dst::pipeline::step` (see `docs/isa.md`).
//! - **Memory** ([`memory`]): the image at 0 (read-only), parameters at `0x7000_0000`
//!   (read-only), frame buffer at `0x7800_0000` (read-write), program at `0x8000_0000`
//!   (read-only), local store at `0xF000_0000` (read-write, per thread). Misaligned and
//!   unmapped accesses are typed errors naming the pc and address.
//!
//! Decoding is hand-written ([`mod@decode`]'s module doc says why); ELF parsing uses the
//! `object` crate ([`elf`]).

pub mod decode;
pub mod elf;
pub mod frame;
pub mod hart;
pub mod isa;
pub mod kernels;
pub mod memory;
pub mod placement;
pub mod run;
#[cfg(test)]
pub(crate) mod tests;
pub mod tp;
pub(crate) mod uop;

pub use crate::hw::fu::FuClass;
pub use decode::{DecodeError, Info, Instr, Latches, Reg, decode};
pub use elf::{ElfError, PROGRAM_BASE, PROGRAM_END, Program};
pub use hart::{CANONICAL_NAN, DstLatch, ExecError, Hart, MemAccess, Retired};
pub use isa::Op;
pub use memory::{
    FRAME_BUFFER_ADDR, FrameMemory, GLOBAL_REGISTERS, ImageView, LOCAL_STORE_ADDR, MemFault,
    Memory, PARAMS_ADDR,
};
pub use run::{RunError, RunStats, run_counting, run_frame, run_to_halt};
