//! One hardware thread (a TP's thread): architectural state and the functional executor.

use super::decode::{CSR_FCSR, CSR_FRM, Info, Instr, decode};
use super::elf::Program;
use super::isa::Op;
use super::isa::PIPE_INPUT_WORDS;
use super::memory::{LOCAL_STORE_ADDR, MemFault, Memory};
use crate::hw::fu::FuClass;
use dualsplit_accel::cwbvh::{CwNode, NODE_WORDS as CW_NODE_WORDS};
use dualsplit_accel::dst::HeaderOffset;
use dualsplit_accel::dst::pipeline::{PipelineInput, step as dst_step};
use dualsplit_accel::dstq::unit::unit_step as dstq_unit_step;
use dualsplit_geometry::{Ray, RayPre, Triangle, Vec3};

/// RISC-V's canonical NaN, the result of every arithmetic instruction whose result is NaN,
/// and the "miss" result of `rt.box` and `rt.tri`.
pub const CANONICAL_NAN: u32 = 0x7FC0_0000;

/// A memory access made by a retired instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct MemAccess {
    /// Byte address of the first byte.
    pub addr: u32,
    /// Number of 32-bit words touched (1 for byte and half-word accesses; 6, 6N, 9 or 3
    /// for `rt.box`, `rt.boxn`, `rt.tri`, `rt.dst`); 0 when the instruction made no access.
    pub words: u8,
    /// `true` for a store.
    pub store: bool,
    /// `true` when the access is to the TP's local store (not through the L1).
    pub local: bool,
}

impl MemAccess {
    /// No access.
    pub const NONE: MemAccess = MemAccess {
        addr: 0,
        words: 0,
        store: false,
        local: false,
    };
    /// `true` when there was an access.
    #[inline]
    pub fn is_some(&self) -> bool {
        self.words != 0
    }
}

/// What a timing model needs from one executed instruction. `Copy`, 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Retired {
    /// Functional-unit class (loads and stores to the local store are
    /// [`FuClass::LocalLoad`]/[`FuClass::LocalStore`]), registers read and written, latches.
    pub info: Info,
    /// The memory access, if any.
    pub mem: MemAccess,
    /// A taken branch or a jump.
    pub taken: bool,
}

impl Retired {
    /// The functional-unit class.
    #[inline]
    pub fn fu(&self) -> FuClass {
        self.info.fu
    }
    /// `true` for `ebreak`.
    #[inline]
    pub fn is_halt(&self) -> bool {
        self.info.fu == FuClass::Halt
    }
}

/// An instruction that could not execute. Every variant names the pc.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExecError {
    /// The pc is misaligned or outside the program's text.
    #[error("pc {pc:#010x}: instruction fetch outside the program's text")]
    Fetch {
        /// The pc.
        pc: u32,
    },
    /// The word at the pc does not decode.
    #[error("pc {pc:#010x}: illegal instruction {word:#010x} ({reason})")]
    Illegal {
        /// The pc.
        pc: u32,
        /// The word.
        word: u32,
        /// Why it does not decode.
        reason: &'static str,
    },
    /// A misaligned load or store (words and memory operands need 4-byte alignment,
    /// half-words 2).
    #[error("pc {pc:#010x}: misaligned {bytes}-byte access at {addr:#010x}")]
    Misaligned {
        /// The pc.
        pc: u32,
        /// The address.
        addr: u32,
        /// Access size in bytes.
        bytes: u32,
    },
    /// An access a read-only view of memory does not hold ([`MemFault::Elsewhere`]): the
    /// event loop runs the instruction again in its commit phase; never a frame's error.
    #[error("pc {pc:#010x}: access to {addr:#010x} outside the read-only view")]
    Elsewhere {
        /// The pc.
        pc: u32,
        /// The address.
        addr: u32,
    },
    /// A load or store to an address no region maps.
    #[error("pc {pc:#010x}: access to unmapped address {addr:#010x}")]
    Unmapped {
        /// The pc.
        pc: u32,
        /// The address.
        addr: u32,
    },
    /// A store to a read-only region (image, parameters, program).
    #[error("pc {pc:#010x}: store to read-only address {addr:#010x}")]
    ReadOnly {
        /// The pc.
        pc: u32,
        /// The address.
        addr: u32,
    },
    /// `rt.atominc` on a global register that does not exist.
    #[error("pc {pc:#010x}: no global register {index}")]
    NoGlobal {
        /// The pc.
        pc: u32,
        /// The register index.
        index: u32,
    },
    /// `rt.setk` with an axis field above 2, or bits above bit 5.
    #[error("pc {pc:#010x}: rt.setk value {value:#x} is not kx | ky << 2 | kz << 4 with axes 0-2")]
    BadAxes {
        /// The pc.
        pc: u32,
        /// `x[rs1]`.
        value: u32,
    },
    /// A CSR write that sets `frm` to a mode other than RNE.
    #[error("pc {pc:#010x}: frm set to {rm} (only round-to-nearest-even is modelled)")]
    RoundingMode {
        /// The pc.
        pc: u32,
        /// The mode written.
        rm: u32,
    },
}

/// The DST latch `D`: the outputs of the last `rt.dst` other than its code and offset.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DstLatch {
    /// `t_min_out`.
    pub t_min_out: f32,
    /// `t_max_out`.
    pub t_max_out: f32,
    /// `offset_stack`.
    pub offset_stack: u32,
    /// The return code of the last `rt.dstqp` (`rt.dst` and `rt.dstp` return theirs in
    /// `rd` and leave this 0).
    pub code: u32,
}

/// One hardware thread's architectural state.
#[derive(Clone, Debug)]
pub struct Hart {
    /// Integer registers (`x[0]` is always 0).
    pub x: [u32; 32],
    /// Float registers, as f32 bits.
    pub f: [u32; 32],
    /// Program counter.
    pub pc: u32,
    /// The ray register set `R` (`ray.origin`, `inv_dir`, `neg`, `k`, `shear`; `ray.dir`,
    /// `t_min`, `t_max` are not part of `R` and stay as constructed).
    pub ray: RayPre,
    /// The box latch `B`.
    pub box_latch: [f32; 8],
    /// The exit distance of the last `rt.box` (`B.exit`, read by `rt.boxget 8`).
    pub box_exit: f32,
    /// The pipeline input registers `P` (written by `rt.ldp`, read by the register forms).
    pub pipe_in: [u32; PIPE_INPUT_WORDS],
    /// The DST latch `D`.
    pub dst_latch: DstLatch,
    /// The random key `K` of `rt.srand` (pixel x, y, sample).
    pub rand_key: [u32; 3],
    /// The TP's private local store, at [`LOCAL_STORE_ADDR`].
    pub local: Box<[u8]>,
    /// Set by `ebreak`.
    pub halted: bool,
}

/// The initial ray register set: origin 0, inverse direction +∞ (direction +0), axes
/// (0, 1, 2), shear 0.
pub fn initial_ray() -> RayPre {
    RayPre {
        ray: Ray::new(Vec3::ZERO, Vec3::ZERO),
        inv_dir: Vec3::INFINITY,
        neg: [false; 3],
        k: [0, 1, 2],
        shear: Vec3::ZERO,
    }
}

/// `rt.rand`'s unit: the renderer's random number (`dualsplit_render`'s per-sample
/// generator: `hash_u32s(&[x, y, sample, bounce, seed, dim]) >> 8` as a float in `[0, 1)`),
/// as f32 bits, for the key `K = (x, y, sample)`.
#[inline]
pub fn rt_rand(key: [u32; 3], bounce: u32, seed: u32, dim: u32) -> u32 {
    let h = dualsplit_geometry::hash_u32s(&[key[0], key[1], key[2], bounce, seed, dim]);
    ((h >> 8) as f32 * (1.0 / 16_777_216.0)).to_bits()
}

#[inline(always)]
fn canon(v: f32) -> u32 {
    if v.is_nan() {
        CANONICAL_NAN
    } else {
        v.to_bits()
    }
}

/// `fmin.s` (RISC-V F, v2.2): a NaN operand is ignored unless both are NaN (then the
/// canonical NaN); −0 < +0.
#[inline]
pub fn fmin(a: u32, b: u32) -> u32 {
    let (x, y) = (f32::from_bits(a), f32::from_bits(b));
    match (x.is_nan(), y.is_nan()) {
        (true, true) => CANONICAL_NAN,
        (true, false) => b,
        (false, true) => a,
        _ if x < y => a,
        _ if y < x => b,
        _ => a | b, // equal: only ±0 differ, and −0 (sign bit set) is the smaller
    }
}

/// `fmax.s` (RISC-V F, v2.2): a NaN operand is ignored unless both are NaN (then the
/// canonical NaN); +0 > −0.
#[inline]
pub fn fmax(a: u32, b: u32) -> u32 {
    let (x, y) = (f32::from_bits(a), f32::from_bits(b));
    match (x.is_nan(), y.is_nan()) {
        (true, true) => CANONICAL_NAN,
        (true, false) => b,
        (false, true) => a,
        _ if x > y => a,
        _ if y > x => b,
        _ => a & b, // equal: +0 (sign bit clear) is the larger
    }
}

/// `fclass.s`: the one-hot class mask.
pub fn fclass(a: u32) -> u32 {
    let v = f32::from_bits(a);
    let neg = a >> 31 != 0;
    let bit = if v.is_nan() {
        if a & 0x0040_0000 != 0 { 9 } else { 8 }
    } else if v.is_infinite() {
        if neg { 0 } else { 7 }
    } else if v == 0.0 {
        if neg { 3 } else { 4 }
    } else if v.is_subnormal() {
        if neg { 2 } else { 5 }
    } else if neg {
        1
    } else {
        6
    };
    1 << bit
}

/// Rounds `v` to an integral value by the static rounding mode `rm` (0 RNE, 1 RTZ, 2 RDN,
/// 3 RUP, 4 RMM, 7 dynamic = RNE).
#[inline]
fn round_rm(v: f32, rm: i32) -> f32 {
    match rm {
        1 => v.trunc(),
        2 => v.floor(),
        3 => v.ceil(),
        4 => v.round(),
        _ => v.round_ties_even(),
    }
}

/// `fcvt.w.s`: saturating, NaN → `i32::MAX`.
#[inline]
pub fn fcvt_w_s(a: u32, rm: i32) -> u32 {
    let v = f32::from_bits(a);
    if v.is_nan() {
        i32::MAX as u32
    } else {
        round_rm(v, rm) as i32 as u32
    }
}

/// `fcvt.wu.s`: saturating, NaN → `u32::MAX`.
#[inline]
pub fn fcvt_wu_s(a: u32, rm: i32) -> u32 {
    let v = f32::from_bits(a);
    if v.is_nan() {
        u32::MAX
    } else {
        round_rm(v, rm) as u32
    }
}

impl Hart {
    /// A thread at `prog`'s entry with a zeroed local store of `local_store_bytes` bytes and
    /// `sp` (`x2`) at its top.
    pub fn new(prog: &Program, local_store_bytes: u32) -> Hart {
        let mut x = [0; 32];
        x[2] = LOCAL_STORE_ADDR.wrapping_add(local_store_bytes);
        Hart {
            x,
            f: [0; 32],
            pc: prog.entry,
            ray: initial_ray(),
            box_latch: [0.0; 8],
            box_exit: 0.0,
            pipe_in: [0; PIPE_INPUT_WORDS],
            dst_latch: DstLatch::default(),
            rand_key: [0; 3],
            local: vec![0; local_store_bytes as usize].into_boxed_slice(),
            halted: false,
        }
    }

    /// Float register `f[n]` as f32.
    #[inline]
    pub fn fr(&self, n: usize) -> f32 {
        f32::from_bits(self.f[n])
    }

    /// Resets the thread to `prog`'s entry: registers, latches and ray registers to their
    /// initial values, `sp` to the local store's top; the local store keeps its bytes.
    pub fn reset(&mut self, prog: &Program) {
        self.x = [0; 32];
        self.x[2] = LOCAL_STORE_ADDR.wrapping_add(self.local.len() as u32);
        self.f = [0; 32];
        self.pc = prog.entry;
        self.ray = initial_ray();
        self.box_latch = [0.0; 8];
        self.box_exit = 0.0;
        self.pipe_in = [0; PIPE_INPUT_WORDS];
        self.dst_latch = DstLatch::default();
        self.halted = false;
    }

    #[inline(always)]
    fn fault(&self, f: MemFault, addr: u32, index: u32) -> ExecError {
        let pc = self.pc;
        match f {
            MemFault::Unmapped => ExecError::Unmapped { pc, addr },
            MemFault::ReadOnly => ExecError::ReadOnly { pc, addr },
            MemFault::NoGlobal => ExecError::NoGlobal { pc, index },
            MemFault::Elsewhere => ExecError::Elsewhere { pc, addr },
        }
    }

    /// Checks that `addr` is aligned to its `bytes` and notes the one-word access in `acc`;
    /// the offset in the local store when `addr` is the local store's.
    #[inline(always)]
    fn begin_access(
        &self,
        addr: u32,
        bytes: u32,
        store: bool,
        acc: &mut MemAccess,
    ) -> Result<Option<usize>, ExecError> {
        if addr & (bytes - 1) != 0 {
            return Err(ExecError::Misaligned {
                pc: self.pc,
                addr,
                bytes,
            });
        }
        let local = addr >= LOCAL_STORE_ADDR;
        *acc = MemAccess {
            addr,
            words: 1,
            store,
            local,
        };
        Ok(local.then(|| (addr - LOCAL_STORE_ADDR) as usize))
    }

    /// Loads `N` bytes at `addr` (aligned to `N`): local store, program, or global memory.
    #[inline(always)]
    fn load<const N: usize, M: Memory>(
        &self,
        prog: &Program,
        mem: &mut M,
        addr: u32,
        acc: &mut MemAccess,
    ) -> Result<[u8; N], ExecError> {
        if let Some(o) = self.begin_access(addr, N as u32, false, acc)? {
            return self
                .local
                .get(o..o + N)
                .and_then(|s| s.try_into().ok())
                .ok_or(ExecError::Unmapped { pc: self.pc, addr });
        }
        if addr >= super::PROGRAM_BASE {
            return prog
                .read(addr, N)
                .and_then(|s| s.try_into().ok())
                .ok_or(ExecError::Unmapped { pc: self.pc, addr });
        }
        mem.load::<N>(addr).map_err(|f| self.fault(f, addr, 0))
    }

    /// Stores `N` bytes at `addr` (aligned to `N`): local store or global memory.
    #[inline(always)]
    fn store<const N: usize, M: Memory>(
        &mut self,
        mem: &mut M,
        addr: u32,
        bytes: [u8; N],
        acc: &mut MemAccess,
    ) -> Result<(), ExecError> {
        if let Some(o) = self.begin_access(addr, N as u32, true, acc)? {
            let pc = self.pc;
            self.local
                .get_mut(o..o + N)
                .ok_or(ExecError::Unmapped { pc, addr })?
                .copy_from_slice(&bytes);
            return Ok(());
        }
        if addr >= super::PROGRAM_BASE {
            return Err(if prog_maps(addr) {
                ExecError::ReadOnly { pc: self.pc, addr }
            } else {
                ExecError::Unmapped { pc: self.pc, addr }
            });
        }
        mem.store::<N>(addr, bytes)
            .map_err(|f| self.fault(f, addr, 0))
    }

    /// Reads the `out.len()` words of a memory operand at `addr` (4-aligned).
    #[inline(always)]
    fn operand_words<M: Memory>(
        &self,
        prog: &Program,
        mem: &mut M,
        addr: u32,
        out: &mut [u32],
        acc: &mut MemAccess,
    ) -> Result<(), ExecError> {
        if addr & 3 != 0 {
            return Err(ExecError::Misaligned {
                pc: self.pc,
                addr,
                bytes: 4,
            });
        }
        *acc = MemAccess {
            addr,
            words: out.len() as u8,
            store: false,
            local: addr >= LOCAL_STORE_ADDR,
        };
        if addr < super::PROGRAM_BASE {
            return mem
                .load_words(addr, out)
                .map_err(|f| self.fault(f, addr, 0));
        }
        let bytes = if addr >= LOCAL_STORE_ADDR {
            let o = (addr - LOCAL_STORE_ADDR) as usize;
            self.local.get(o..o + 4 * out.len())
        } else {
            prog.read(addr, 4 * out.len())
        }
        .ok_or(ExecError::Unmapped { pc: self.pc, addr })?;
        for (w, c) in out.iter_mut().zip(bytes.chunks_exact(4)) {
            *w = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        }
        Ok(())
    }

    /// The node words of a ray-tracing instruction: from `P` for a register form
    /// (`from_pipe`), else the memory operand at `addr`.
    #[inline(always)]
    fn node_words<M: Memory>(
        &self,
        from_pipe: bool,
        prog: &Program,
        mem: &mut M,
        addr: u32,
        out: &mut [u32],
        acc: &mut MemAccess,
    ) -> Result<(), ExecError> {
        if from_pipe {
            out.copy_from_slice(&self.pipe_in[..out.len()]);
            Ok(())
        } else {
            self.operand_words(prog, mem, addr, out, acc)
        }
    }

    /// The box test of `rt.box`/`rt.boxn` on the six words `b` (min xyz, max xyz): the
    /// entry distance on a hit, else the canonical NaN.
    #[inline(always)]
    fn box_test(&self, b: &[u32], t_lo: f32, t_hi: f32) -> (bool, u32, f32) {
        let v = |k: usize| f32::from_bits(b[k]);
        let (entry, exit) = self.ray.slab(
            Vec3::new(v(0), v(1), v(2)),
            Vec3::new(v(3), v(4), v(5)),
            t_lo,
            t_hi,
        );
        if entry <= exit {
            (true, entry.to_bits(), exit)
        } else {
            (false, CANONICAL_NAN, exit)
        }
    }

    /// `rt.boxn`'s tests of `n` boxes (`bx(k)`: box `k`'s six words): the entries to the box
    /// latch, the hit mask returned.
    #[inline(always)]
    fn wide_box_test<'b>(
        &mut self,
        n: usize,
        bx: impl Fn(usize) -> &'b [u32],
        t_lo: f32,
        t_hi: f32,
    ) -> u32 {
        let mut mask = 0;
        for k in 0..n {
            let (hit, entry, _) = self.box_test(bx(k), t_lo, t_hi);
            mask |= (hit as u32) << k;
            self.box_latch[k] = f32::from_bits(entry);
        }
        mask
    }

    /// Executes one instruction at the pc (functionally) and returns what a timing model
    /// needs about it. After `ebreak` the thread is [`Hart::halted`] and the pc stays on
    /// the `ebreak`; stepping again retires it again.
    #[inline]
    pub fn step<M: Memory>(&mut self, prog: &Program, mem: &mut M) -> Result<Retired, ExecError> {
        let pc = self.pc;
        let Some(ins) = prog.fetch(pc) else {
            return Err(ExecError::Fetch { pc });
        };
        let ins = *ins;
        self.exec(&ins, prog, mem)
    }

    /// Executes `ins`, the instruction at the pc (fetched from `prog` by the caller), as
    /// [`Hart::step`] does.
    #[inline]
    pub fn exec<M: Memory>(
        &mut self,
        ins: &Instr,
        prog: &Program,
        mem: &mut M,
    ) -> Result<Retired, ExecError> {
        let (acc, taken) = self.execute(ins, prog, mem)?;
        let mut info = ins.info;
        info.fu = executed_class(info.fu, &acc);
        Ok(Retired {
            info,
            mem: acc,
            taken,
        })
    }

    /// Executes `ins`, an instruction [`Hart::exec_register`] does not run (it returned
    /// `None`), as [`Hart::exec`] does, returning only its memory access (a timing model
    /// that has the instruction's [`Info`] needs nothing else). The TP's executor: it
    /// dispatches on the op once, among those instructions only.
    #[inline(never)]
    pub(crate) fn exec_access<M: Memory>(
        &mut self,
        ins: &Instr,
        prog: &Program,
        mem: &mut M,
    ) -> Result<MemAccess, ExecError> {
        self.execute_other(ins, prog, mem)
    }

    /// Executes `ins` when it is a register operation: integer and floating-point
    /// arithmetic, `lui`, `auipc`, branches, jumps, `fence`, `rt.rcp` and `rt.rand` (no
    /// memory access, no latch, no error); returns whether it was a taken branch or a jump.
    /// Returns `None`, changing nothing, for any other instruction, which the out-of-line
    /// executor runs ([`Hart::exec`]). The `rv32` timing model calls it inline first.
    #[inline(always)]
    pub fn exec_register(&mut self, ins: &Instr) -> Option<bool> {
        use Op::*;
        let (pc, imm) = (self.pc, ins.imm);
        // `& 31` lets the compiler drop the register files' bounds checks.
        let (rd, rs1, rs2, rs3) = (
            ins.rd as usize & 31,
            ins.rs1 as usize & 31,
            ins.rs2 as usize & 31,
            ins.rs3 as usize & 31,
        );
        let a = || self.x[rs1];
        let b = || self.x[rs2];
        let fa = || f32::from_bits(self.f[rs1]);
        let fb = || f32::from_bits(self.f[rs2]);
        let fc = || f32::from_bits(self.f[rs3]);
        let mut next = pc.wrapping_add(4);
        let link = next;
        let mut taken = false;
        let mut branch = |c: bool| {
            if c {
                next = pc.wrapping_add(imm as u32);
                taken = true;
            }
        };
        // The value of `x[rd]` (`Ok`) or `f[rd]` (`Err`), if any.
        let out: Option<Result<u32, u32>> = match ins.op {
            Lui => Some(Ok(imm as u32)),
            Auipc => Some(Ok(pc.wrapping_add(imm as u32))),
            Jal => {
                branch(true);
                Some(Ok(link))
            }
            Jalr => {
                // Read before the link write (rd may be rs1).
                next = a().wrapping_add(imm as u32) & !1;
                taken = true;
                Some(Ok(link))
            }
            Beq => {
                branch(a() == b());
                None
            }
            Bne => {
                branch(a() != b());
                None
            }
            Blt => {
                branch((a() as i32) < (b() as i32));
                None
            }
            Bge => {
                branch((a() as i32) >= (b() as i32));
                None
            }
            Bltu => {
                branch(a() < b());
                None
            }
            Bgeu => {
                branch(a() >= b());
                None
            }
            Addi => Some(Ok(a().wrapping_add(imm as u32))),
            Slti => Some(Ok(((a() as i32) < imm) as u32)),
            Sltiu => Some(Ok((a() < imm as u32) as u32)),
            Xori => Some(Ok(a() ^ imm as u32)),
            Ori => Some(Ok(a() | imm as u32)),
            Andi => Some(Ok(a() & imm as u32)),
            Slli => Some(Ok(a() << imm)),
            Srli => Some(Ok(a() >> imm)),
            Srai => Some(Ok(((a() as i32) >> imm) as u32)),
            Add => Some(Ok(a().wrapping_add(b()))),
            Sub => Some(Ok(a().wrapping_sub(b()))),
            Sll => Some(Ok(a() << (b() & 31))),
            Slt => Some(Ok(((a() as i32) < (b() as i32)) as u32)),
            Sltu => Some(Ok((a() < b()) as u32)),
            Xor => Some(Ok(a() ^ b())),
            Srl => Some(Ok(a() >> (b() & 31))),
            Sra => Some(Ok(((a() as i32) >> (b() & 31)) as u32)),
            Or => Some(Ok(a() | b())),
            And => Some(Ok(a() & b())),
            Mul => Some(Ok(a().wrapping_mul(b()))),
            Mulh => Some(Ok(((a() as i32 as i64 * b() as i32 as i64) >> 32) as u32)),
            Mulhsu => Some(Ok(((a() as i32 as i64 * b() as i64) >> 32) as u32)),
            Mulhu => Some(Ok(((a() as u64 * b() as u64) >> 32) as u32)),
            Div => Some(Ok(if b() == 0 {
                u32::MAX
            } else {
                (a() as i32).wrapping_div(b() as i32) as u32
            })),
            Divu => Some(Ok(a().checked_div(b()).unwrap_or(u32::MAX))),
            Rem => Some(Ok(if b() == 0 {
                a()
            } else {
                (a() as i32).wrapping_rem(b() as i32) as u32
            })),
            Remu => Some(Ok(if b() == 0 { a() } else { a() % b() })),
            Fence => None,
            FmaddS => Some(Err(canon(fa().mul_add(fb(), fc())))),
            FmsubS => Some(Err(canon(fa().mul_add(fb(), -fc())))),
            FnmsubS => Some(Err(canon((-fa()).mul_add(fb(), fc())))),
            FnmaddS => Some(Err(canon((-fa()).mul_add(fb(), -fc())))),
            FaddS => Some(Err(canon(fa() + fb()))),
            FsubS => Some(Err(canon(fa() - fb()))),
            FmulS => Some(Err(canon(fa() * fb()))),
            FdivS => Some(Err(canon(fa() / fb()))),
            FsqrtS => Some(Err(canon(fa().sqrt()))),
            FsgnjS => Some(Err(
                (self.f[rs1] & 0x7FFF_FFFF) | (self.f[rs2] & 0x8000_0000)
            )),
            FsgnjnS => Some(Err(
                (self.f[rs1] & 0x7FFF_FFFF) | (!self.f[rs2] & 0x8000_0000)
            )),
            FsgnjxS => Some(Err(self.f[rs1] ^ (self.f[rs2] & 0x8000_0000))),
            FminS => Some(Err(fmin(self.f[rs1], self.f[rs2]))),
            FmaxS => Some(Err(fmax(self.f[rs1], self.f[rs2]))),
            FcvtWS => Some(Ok(fcvt_w_s(self.f[rs1], imm))),
            FcvtWuS => Some(Ok(fcvt_wu_s(self.f[rs1], imm))),
            FmvXW => Some(Ok(self.f[rs1])),
            FeqS => Some(Ok((fa() == fb()) as u32)),
            FltS => Some(Ok((fa() < fb()) as u32)),
            FleS => Some(Ok((fa() <= fb()) as u32)),
            FclassS => Some(Ok(fclass(self.f[rs1]))),
            FcvtSW => Some(Err((a() as i32 as f32).to_bits())),
            FcvtSWu => Some(Err((a() as f32).to_bits())),
            FmvWX => Some(Err(a())),
            RtRcp => Some(Err(canon(1.0 / fa()))),
            RtRand => Some(Err(rt_rand(self.rand_key, a(), b(), imm as u32))),
            _ => return None,
        };
        match out {
            Some(Ok(v)) if rd != 0 => self.x[rd] = v,
            Some(Err(v)) => self.f[rd] = v,
            _ => {}
        }
        self.pc = next;
        Some(taken)
    }

    /// Executes `ins`: its memory access and whether it was a taken branch or a jump.
    #[inline(always)]
    fn execute<M: Memory>(
        &mut self,
        ins: &Instr,
        prog: &Program,
        mem: &mut M,
    ) -> Result<(MemAccess, bool), ExecError> {
        if let Some(taken) = self.exec_register(ins) {
            return Ok((MemAccess::NONE, taken));
        }
        self.execute_other(ins, prog, mem).map(|acc| (acc, false))
    }

    /// Executes `ins`, which is not a register operation ([`Hart::exec_register`] returned
    /// `None` for it): a load, store, ray-tracing, latch or system instruction.
    #[inline(always)]
    fn execute_other<M: Memory>(
        &mut self,
        ins: &Instr,
        prog: &Program,
        mem: &mut M,
    ) -> Result<MemAccess, ExecError> {
        let pc = self.pc;
        let (op, imm) = (ins.op, ins.imm);
        // Register numbers are read where used; `& 31` lets the compiler drop the register
        // files' bounds checks.
        macro_rules! rd {
            () => {
                (ins.rd as usize & 31)
            };
        }
        let rs1 = ins.rs1 as usize & 31;
        macro_rules! rs2 {
            () => {
                (ins.rs2 as usize & 31)
            };
        }
        macro_rules! rs3 {
            () => {
                (ins.rs3 as usize & 31)
            };
        }
        let mut next = pc.wrapping_add(4);
        let mut acc = MemAccess::NONE;
        // Operands are read by the arms that use them (reading all five up front costs
        // more than the dispatch).
        macro_rules! a {
            () => {
                self.x[rs1]
            };
        }
        macro_rules! b {
            () => {
                self.x[rs2!()]
            };
        }
        macro_rules! fa {
            () => {
                f32::from_bits(self.f[rs1])
            };
        }
        macro_rules! fb {
            () => {
                f32::from_bits(self.f[rs2!()])
            };
        }
        macro_rules! fc {
            () => {
                f32::from_bits(self.f[rs3!()])
            };
        }
        macro_rules! ea {
            () => {
                self.x[rs1].wrapping_add(imm as u32)
            };
        }
        macro_rules! wx {
            ($v:expr) => {{
                self.x[rd!()] = $v;
            }};
        }
        macro_rules! wf {
            ($v:expr) => {{
                self.f[rd!()] = $v;
            }};
        }
        use Op::*;
        match op {
            Lb => wx!(self.load::<1, M>(prog, mem, ea!(), &mut acc)?[0] as i8 as i32 as u32),
            Lbu => wx!(self.load::<1, M>(prog, mem, ea!(), &mut acc)?[0] as u32),
            Lh => {
                wx!(
                    i16::from_le_bytes(self.load::<2, M>(prog, mem, ea!(), &mut acc)?) as i32
                        as u32
                )
            }
            Lhu => wx!(u16::from_le_bytes(self.load::<2, M>(prog, mem, ea!(), &mut acc)?) as u32),
            Lw => wx!(u32::from_le_bytes(self.load::<4, M>(
                prog,
                mem,
                ea!(),
                &mut acc
            )?)),
            Flw => wf!(u32::from_le_bytes(self.load::<4, M>(
                prog,
                mem,
                ea!(),
                &mut acc
            )?)),
            Sb => self.store::<1, M>(mem, ea!(), [b!() as u8], &mut acc)?,
            Sh => self.store::<2, M>(mem, ea!(), (b!() as u16).to_le_bytes(), &mut acc)?,
            Sw => self.store::<4, M>(mem, ea!(), b!().to_le_bytes(), &mut acc)?,
            Fsw => {
                let v = self.f[rs2!()];
                self.store::<4, M>(mem, ea!(), v.to_le_bytes(), &mut acc)?
            }
            Ebreak => {
                self.halted = true;
                next = pc;
            }
            Csrrw | Csrrs | Csrrc | Csrrwi | Csrrsi | Csrrci => {
                // fflags, frm and fcsr all read 0 (fflags not modelled, frm = RNE).
                let src = if matches!(op, Csrrw | Csrrs | Csrrc) {
                    a!()
                } else {
                    rs1 as u32
                };
                let writes = matches!(op, Csrrw | Csrrwi) || rs1 != 0;
                let new = match op {
                    Csrrw | Csrrwi => src,
                    Csrrs | Csrrsi => src,
                    _ => 0,
                };
                let rm = match imm {
                    CSR_FRM => new & 7,
                    CSR_FCSR => (new >> 5) & 7,
                    _ => 0,
                };
                if writes && rm != 0 {
                    return Err(ExecError::RoundingMode { pc, rm });
                }
                wx!(0);
            }
            RtSetOrg => self.ray.ray.origin = Vec3::new(fa!(), fb!(), fc!()),
            RtSetInv => {
                self.ray.inv_dir = Vec3::new(fa!(), fb!(), fc!());
                self.ray.neg = [
                    fa!().is_sign_negative(),
                    fb!().is_sign_negative(),
                    fc!().is_sign_negative(),
                ];
            }
            RtSetShear => self.ray.shear = Vec3::new(fa!(), fb!(), fc!()),
            RtSetK => {
                let k = [a!() & 3, (a!() >> 2) & 3, (a!() >> 4) & 3];
                if a!() >> 6 != 0 || k.contains(&3) {
                    return Err(ExecError::BadAxes { pc, value: a!() });
                }
                self.ray.k = k.map(|v| v as usize);
            }
            RtSRand => self.rand_key = [a!(), b!(), self.x[rs3!()]],
            RtAtomInc => {
                let old = mem.atominc(a!()).map_err(|f| self.fault(f, 0, a!()))?;
                wx!(old);
            }
            RtBox | RtBoxP => {
                let mut w = [0u32; 6];
                self.node_words(op == RtBoxP, prog, mem, a!(), &mut w, &mut acc)?;
                let (_, entry, exit) = self.box_test(&w, fb!(), fc!());
                self.box_exit = exit;
                wf!(entry);
            }
            RtBoxN | RtBoxNP => {
                let n = imm as usize;
                let mut w = [0u32; 48];
                self.node_words(op == RtBoxNP, prog, mem, a!(), &mut w[..6 * n], &mut acc)?;
                let mask = self.wide_box_test(n, |k| &w[6 * k..6 * k + 6], fb!(), fc!());
                wx!(mask);
            }
            RtBoxGet => wf!(match imm {
                0..=7 => self.box_latch[imm as usize],
                _ => self.box_exit,
            }
            .to_bits()),
            RtTri | RtTriP => {
                let mut w = [0u32; 9];
                self.node_words(op == RtTriP, prog, mem, a!(), &mut w, &mut acc)?;
                let v = |k: usize| {
                    Vec3::new(
                        f32::from_bits(w[3 * k]),
                        f32::from_bits(w[3 * k + 1]),
                        f32::from_bits(w[3 * k + 2]),
                    )
                };
                let tri = Triangle {
                    v: [v(0), v(1), v(2)],
                };
                wf!(match tri.intersect(&self.ray, fb!(), fc!()) {
                    Some(h) => h.t.to_bits(),
                    None => CANONICAL_NAN,
                });
            }
            RtDst | RtDstP => {
                let mut w = [0u32; 3];
                self.node_words(op == RtDstP, prog, mem, a!(), &mut w, &mut acc)?;
                let out = dst_step(&PipelineInput {
                    word: HeaderOffset::from_bits(w[0]),
                    p0: f32::from_bits(w[1]),
                    p1: f32::from_bits(w[2]),
                    origin: self.ray.ray.origin.to_array(),
                    inv_dir: self.ray.inv_dir.to_array(),
                    t_min: fb!(),
                    t_max: fc!(),
                });
                self.dst_latch = DstLatch {
                    t_min_out: out.t_min_out,
                    t_max_out: out.t_max_out,
                    offset_stack: out.offset_stack,
                    code: 0,
                };
                wx!(out.code as u32 | (out.offset << 2));
            }
            RtQBoxN | RtQBoxNP => {
                let mut w = [0u32; CW_NODE_WORDS];
                self.node_words(op == RtQBoxNP, prog, mem, a!(), &mut w, &mut acc)?;
                let node = CwNode::read(&w, 0);
                let boxes: [[u32; 6]; 8] =
                    std::array::from_fn(|k| node.box_words(k).map(f32::to_bits));
                let mask = self.wide_box_test(8, |k| &boxes[k], fb!(), fc!());
                wx!(mask);
            }
            RtDstQP => {
                let p = &self.pipe_in;
                let out = dstq_unit_step(
                    [p[32], p[33], p[34], p[35]],
                    [p[36], p[37], p[38]],
                    a!(),
                    self.ray.ray.origin.to_array(),
                    self.ray.inv_dir.to_array(),
                    fb!(),
                    fc!(),
                );
                self.dst_latch = DstLatch {
                    t_min_out: out.t_min_out,
                    t_max_out: out.t_max_out,
                    offset_stack: out.stack,
                    code: out.code as u32,
                };
                wx!(out.next);
            }
            RtLdp => {
                let v = u32::from_le_bytes(self.load::<4, M>(prog, mem, ea!(), &mut acc)?);
                self.pipe_in[(rd!() + 32 * rs2!()) % PIPE_INPUT_WORDS] = v;
            }
            RtDstGet => match imm {
                0 => wf!(self.dst_latch.t_min_out.to_bits()),
                1 => wf!(self.dst_latch.t_max_out.to_bits()),
                2 => wx!(self.dst_latch.offset_stack),
                _ => wx!(self.dst_latch.code),
            },
            Illegal => {
                let word = imm as u32;
                let reason = decode(word).err().map_or("illegal", |e| e.reason);
                return Err(ExecError::Illegal { pc, word, reason });
            }
            _ => unreachable!("{op:?} is a register operation (Hart::exec_register)"),
        }
        self.x[0] = 0;
        self.pc = next;
        Ok(acc)
    }
}

/// The class an instruction of class `fu` executed on, given its access `acc`: a load or
/// store that addressed the local store is [`FuClass::LocalLoad`] or
/// [`FuClass::LocalStore`].
#[inline]
pub fn executed_class(fu: FuClass, acc: &MemAccess) -> FuClass {
    match fu {
        FuClass::Load if acc.local => FuClass::LocalLoad,
        FuClass::Store if acc.local => FuClass::LocalStore,
        f => f,
    }
}

/// `true` when `addr` is in the program region (stores there are read-only faults).
#[inline]
fn prog_maps(addr: u32) -> bool {
    (super::PROGRAM_BASE..super::PROGRAM_END).contains(&addr)
}
