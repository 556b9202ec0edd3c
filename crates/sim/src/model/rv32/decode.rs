//! Decoder: one 32-bit RV32IMF word (or a ray-tracing instruction of `docs/isa.md`) into a
//! pre-decoded [`Instr`].
//!
//! Hand-written: one `match` on the major opcode and the function fields. A decoder crate
//! (`riscv-decode`, `raki`) would give a general instruction enum that we would translate
//! again into ours (operand kinds, functional-unit class, the custom opcode space, the
//! rounding-mode rule below), so the crate would save little and add a layer; the table
//! here is the RISC-V unprivileged spec's (v20191213, ch. 2, 7, 11, 24) and is tested per
//! opcode in `tests.rs`.
//!
//! Every decoded instruction carries its static [`Info`] (functional-unit class, registers
//! read and written, latches touched), so the executor copies it into [`super::Retired`]
//! without recomputing it.
//!
//! Rounding modes: `frm` is fixed to round-to-nearest-even, so arithmetic instructions
//! accept `rm = 0` (RNE) and `rm = 7` (dynamic, i.e. RNE) only; any other static mode is a
//! [`DecodeError`]. The float-to-integer conversions `fcvt.w.s`/`fcvt.wu.s` accept every
//! valid mode (0–4, 7), because C's `(int)x` compiles to `fcvt.w.s …, rtz`.

use super::isa::{OPCODE_CUSTOM0, OPCODE_CUSTOM1, OPCODE_CUSTOM2, OPCODE_CUSTOM3, Op};
use crate::hw::fu::FuClass;
use std::fmt;

/// A register operand: an integer register `x0..x31`, a float register `f0..f31`, or none.
///
/// `x0` is never reported as a source or a destination (it is always ready and never
/// written), so a timing model's scoreboard can index by [`Reg::index`] without special
/// cases.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Reg(u8);

impl Reg {
    /// No register.
    pub const NONE: Reg = Reg(0xFF);
    /// Integer register `x[n]` (`x0` maps to [`Reg::NONE`]).
    #[inline]
    pub const fn x(n: u8) -> Reg {
        if n == 0 { Reg::NONE } else { Reg(n & 31) }
    }
    /// Float register `f[n]`.
    #[inline]
    pub const fn f(n: u8) -> Reg {
        Reg(32 + (n & 31))
    }
    /// `true` for [`Reg::NONE`].
    #[inline]
    pub const fn is_none(self) -> bool {
        self.0 == 0xFF
    }
    /// A scoreboard index: `0..32` integer, `32..64` float; `None` for no register.
    #[inline]
    pub const fn index(self) -> Option<usize> {
        if self.0 < 64 {
            Some(self.0 as usize)
        } else {
            None
        }
    }
    /// `true` for a float register.
    #[inline]
    pub const fn is_float(self) -> bool {
        self.0 >= 32 && self.0 < 64
    }
}

impl fmt::Debug for Reg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index() {
            None => write!(f, "-"),
            Some(i) if i < 32 => write!(f, "x{i}"),
            Some(i) => write!(f, "f{}", i - 32),
        }
    }
}

/// Bit flags: the per-thread latches an instruction reads or writes (the ray register set
/// `R`, the box latch `B`, the DST latch `D`), so a timing model can order them.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Latches(u8);

impl Latches {
    /// Reads `R`.
    pub const READS_RAY: u8 = 1;
    /// Writes `R`.
    pub const WRITES_RAY: u8 = 2;
    /// Reads `B`.
    pub const READS_BOX: u8 = 4;
    /// Writes `B`.
    pub const WRITES_BOX: u8 = 8;
    /// Reads `D`.
    pub const READS_DST: u8 = 16;
    /// Writes `D`.
    pub const WRITES_DST: u8 = 32;
    /// Reads the pipeline input registers `P`.
    pub const READS_PIPE: u8 = 64;
    /// Writes `P`.
    pub const WRITES_PIPE: u8 = 128;
    /// The raw bits.
    #[inline]
    pub const fn bits(self) -> u8 {
        self.0
    }
    /// `true` when every bit of `flag` is set.
    #[inline]
    pub const fn has(self, flag: u8) -> bool {
        self.0 & flag == flag
    }
    /// Reads the ray registers.
    #[inline]
    pub const fn reads_ray(self) -> bool {
        self.has(Self::READS_RAY)
    }
}

impl fmt::Debug for Latches {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Latches({:#04x})", self.0)
    }
}

/// What a timing model needs to know about an instruction before executing it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Info {
    /// Functional-unit class.
    pub fu: FuClass,
    /// Registers read (up to three; [`Reg::NONE`] for unused slots and `x0`).
    pub src: [Reg; 3],
    /// Register written ([`Reg::NONE`] when none, or `x0`).
    pub dst: Reg,
    /// Latches read and written.
    pub latches: Latches,
}

/// A pre-decoded instruction: the operation, register numbers, immediate and static
/// [`Info`]. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Instr {
    /// The operation.
    pub op: Op,
    /// Destination register number (x or f per `op`).
    pub rd: u8,
    /// First source register number (or the 5-bit immediate of `csrr*i`).
    pub rs1: u8,
    /// Second source register number.
    pub rs2: u8,
    /// Third source register number (R4 format).
    pub rs3: u8,
    /// Immediate (sign-extended, already shifted for U/B/J formats), CSR number, rounding
    /// mode, or sub-operation; see [`Op`].
    pub imm: i32,
    /// Static information for the timing model.
    pub info: Info,
}

const _: () = assert!(std::mem::size_of::<Instr>() <= 16);

/// Why a word does not decode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("illegal instruction word {word:#010x}: {reason}")]
pub struct DecodeError {
    /// The word.
    pub word: u32,
    /// What is wrong with it.
    pub reason: &'static str,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum K {
    N,
    X,
    F,
}

fn reg(k: K, n: u8) -> Reg {
    match k {
        K::N => Reg::NONE,
        K::X => Reg::x(n),
        K::F => Reg::f(n),
    }
}

/// Register kinds (rd, rs1, rs2, rs3), unit and latches of each operation.
fn shape(op: Op, imm: i32) -> (K, K, K, K, FuClass, u8) {
    use FuClass as U;
    use K::*;
    use Op::*;
    let r = Latches::READS_RAY;
    let p = r | Latches::READS_PIPE;
    match op {
        Lui | Auipc => (X, N, N, N, U::IntAlu, 0),
        Jal => (X, N, N, N, U::Branch, 0),
        Jalr => (X, X, N, N, U::Branch, 0),
        Beq | Bne | Blt | Bge | Bltu | Bgeu => (N, X, X, N, U::Branch, 0),
        Lb | Lh | Lw | Lbu | Lhu => (X, X, N, N, U::Load, 0),
        Sb | Sh | Sw => (N, X, X, N, U::Store, 0),
        Addi | Slti | Sltiu | Xori | Ori | Andi | Slli | Srli | Srai => (X, X, N, N, U::IntAlu, 0),
        Add | Sub | Sll | Slt | Sltu | Xor | Srl | Sra | Or | And => (X, X, X, N, U::IntAlu, 0),
        Mul | Mulh | Mulhsu | Mulhu => (X, X, X, N, U::IntMul, 0),
        Div | Divu | Rem | Remu => (X, X, X, N, U::IntDiv, 0),
        Fence => (N, N, N, N, U::IntAlu, 0),
        Ebreak | Illegal => (N, N, N, N, U::Halt, 0),
        Csrrw | Csrrs | Csrrc => (X, X, N, N, U::IntAlu, 0),
        Csrrwi | Csrrsi | Csrrci => (X, N, N, N, U::IntAlu, 0),
        Flw => (F, X, N, N, U::Load, 0),
        Fsw => (N, X, F, N, U::Store, 0),
        FmaddS | FmsubS | FnmsubS | FnmaddS => (F, F, F, F, U::FpFma, 0),
        FaddS | FsubS => (F, F, F, N, U::FpAdd, 0),
        FmulS => (F, F, F, N, U::FpMul, 0),
        FdivS => (F, F, F, N, U::FpDiv, 0),
        FsqrtS => (F, F, N, N, U::FpSqrt, 0),
        FsgnjS | FsgnjnS | FsgnjxS => (F, F, F, N, U::FpMove, 0),
        FminS | FmaxS => (F, F, F, N, U::FpMinMax, 0),
        FcvtWS | FcvtWuS => (X, F, N, N, U::FpConv, 0),
        FmvXW => (X, F, N, N, U::FpMove, 0),
        FeqS | FltS | FleS => (X, F, F, N, U::FpCmp, 0),
        FclassS => (X, F, N, N, U::FpCmp, 0),
        FcvtSW | FcvtSWu => (F, X, N, N, U::FpConv, 0),
        FmvWX => (F, X, N, N, U::FpMove, 0),
        RtSetOrg | RtSetInv | RtSetShear => (N, F, F, F, U::IntAlu, Latches::WRITES_RAY),
        RtSetK => (N, X, N, N, U::IntAlu, Latches::WRITES_RAY),
        RtRcp => (F, F, N, N, U::Rcp, 0),
        RtAtomInc => (X, X, N, N, U::Atomic, 0),
        // The key is a TP register written in program order, read by `rt.rand` issued later.
        RtSRand => (N, X, X, X, U::IntAlu, 0),
        // TRaX's RAND runs on the FP adder (SimTRaX `sim/FPAddSub.cc:25`, `:91`).
        RtRand => (F, X, X, N, U::FpAdd, 0),
        RtBox => (F, X, F, F, U::BoxPipe(1), r | Latches::WRITES_BOX),
        RtBoxN => (X, X, F, F, U::BoxPipe(imm as u8), r | Latches::WRITES_BOX),
        RtBoxGet => (F, N, N, N, U::IntAlu, Latches::READS_BOX),
        RtTri => (F, X, F, F, U::TriPipe, r),
        RtDst => (X, X, F, F, U::DstPipe, r | Latches::WRITES_DST),
        RtDstGet => {
            let rd = if imm >= 2 { X } else { F };
            (rd, N, N, N, U::IntAlu, Latches::READS_DST)
        }
        RtLdp => (N, X, N, N, U::Load, Latches::WRITES_PIPE),
        RtBoxP => (F, N, F, F, U::BoxPipe(1), p | Latches::WRITES_BOX),
        RtBoxNP => (X, N, F, F, U::BoxPipe(imm as u8), p | Latches::WRITES_BOX),
        RtTriP => (F, N, F, F, U::TriPipe, p),
        RtDstP => (X, N, F, F, U::DstPipe, p | Latches::WRITES_DST),
        RtQBoxN => (X, X, F, F, U::BoxPipe(8), r | Latches::WRITES_BOX),
        RtQBoxNP => (X, N, F, F, U::BoxPipe(8), p | Latches::WRITES_BOX),
        RtDstQP => (X, X, F, F, U::DstPipe, p | Latches::WRITES_DST),
    }
}

/// Builds an [`Instr`], zeroing the register fields the operation does not use (so they
/// never create false dependencies) and computing its [`Info`].
pub fn make(op: Op, rd: u8, rs1: u8, rs2: u8, rs3: u8, imm: i32) -> Instr {
    let (krd, k1, k2, k3, fu, latches) = shape(op, imm);
    let keep = |k: K, n: u8| if k == K::N { 0 } else { n & 31 };
    // csrr*i: the rs1 field is an immediate, not a register; keep it.
    let rs1 = if matches!(op, Op::Csrrwi | Op::Csrrsi | Op::Csrrci) {
        rs1 & 31
    } else {
        keep(k1, rs1)
    };
    // rt.ldp: rd and rs2 hold the P index, not registers; keep them.
    let (rd, rs2) = if op == Op::RtLdp {
        (rd & 31, rs2 & 31)
    } else {
        (keep(krd, rd), keep(k2, rs2))
    };
    let rs3 = keep(k3, rs3);
    Instr {
        op,
        rd,
        rs1,
        rs2,
        rs3,
        imm,
        info: Info {
            fu,
            src: [reg(k1, rs1), reg(k2, rs2), reg(k3, rs3)],
            dst: reg(krd, rd),
            latches: Latches(latches),
        },
    }
}

/// The instruction [`Op::Illegal`] holding `word`.
pub fn illegal(word: u32) -> Instr {
    make(Op::Illegal, 0, 0, 0, 0, word as i32)
}

/// CSR numbers accepted: `fflags`, `frm`, `fcsr`.
pub const CSR_FFLAGS: i32 = 0x001;
/// `frm`.
pub const CSR_FRM: i32 = 0x002;
/// `fcsr`.
pub const CSR_FCSR: i32 = 0x003;

/// Decodes one instruction word.
pub fn decode(w: u32) -> Result<Instr, DecodeError> {
    let err = |reason| DecodeError { word: w, reason };
    let opcode = w & 0x7F;
    let rd = ((w >> 7) & 31) as u8;
    let f3 = (w >> 12) & 7;
    let rs1 = ((w >> 15) & 31) as u8;
    let rs2 = ((w >> 20) & 31) as u8;
    let rs3 = (w >> 27) as u8;
    let f7 = w >> 25;
    let f2 = (w >> 25) & 3;
    let imm_i = (w as i32) >> 20;
    let imm_s = (((w as i32) >> 25) << 5) | ((w >> 7) & 31) as i32;
    let imm_b = (((w as i32) >> 31) << 12)
        | (((w >> 7) & 1) << 11) as i32
        | (((w >> 25) & 0x3F) << 5) as i32
        | (((w >> 8) & 0xF) << 1) as i32;
    let imm_u = (w & 0xFFFF_F000) as i32;
    let imm_j = (((w as i32) >> 31) << 20)
        | (w & 0x000F_F000) as i32
        | (((w >> 20) & 1) << 11) as i32
        | (((w >> 21) & 0x3FF) << 1) as i32;
    let r = |op| Ok(make(op, rd, rs1, rs2, rs3, 0));
    let i = |op| Ok(make(op, rd, rs1, 0, 0, imm_i));
    let rne = |op| {
        if f3 == 0 || f3 == 7 {
            Ok(make(op, rd, rs1, rs2, rs3, 0))
        } else {
            Err(err(
                "static rounding mode other than RNE (frm is fixed to RNE)",
            ))
        }
    };
    use Op::*;
    match opcode {
        0x37 => Ok(make(Lui, rd, 0, 0, 0, imm_u)),
        0x17 => Ok(make(Auipc, rd, 0, 0, 0, imm_u)),
        0x6F => Ok(make(Jal, rd, 0, 0, 0, imm_j)),
        0x67 if f3 == 0 => i(Jalr),
        0x63 => {
            let op = match f3 {
                0 => Beq,
                1 => Bne,
                4 => Blt,
                5 => Bge,
                6 => Bltu,
                7 => Bgeu,
                _ => return Err(err("branch funct3")),
            };
            Ok(make(op, 0, rs1, rs2, 0, imm_b))
        }
        0x03 => match f3 {
            0 => i(Lb),
            1 => i(Lh),
            2 => i(Lw),
            4 => i(Lbu),
            5 => i(Lhu),
            _ => Err(err("load funct3")),
        },
        0x23 => {
            let op = match f3 {
                0 => Sb,
                1 => Sh,
                2 => Sw,
                _ => return Err(err("store funct3")),
            };
            Ok(make(op, 0, rs1, rs2, 0, imm_s))
        }
        0x13 => match f3 {
            0 => i(Addi),
            2 => i(Slti),
            3 => i(Sltiu),
            4 => i(Xori),
            6 => i(Ori),
            7 => i(Andi),
            1 if f7 == 0 => Ok(make(Slli, rd, rs1, 0, 0, rs2 as i32)),
            5 if f7 == 0 => Ok(make(Srli, rd, rs1, 0, 0, rs2 as i32)),
            5 if f7 == 0x20 => Ok(make(Srai, rd, rs1, 0, 0, rs2 as i32)),
            _ => Err(err("shift-immediate funct7")),
        },
        0x33 => {
            let op = match (f7, f3) {
                (0, 0) => Add,
                (0x20, 0) => Sub,
                (0, 1) => Sll,
                (0, 2) => Slt,
                (0, 3) => Sltu,
                (0, 4) => Xor,
                (0, 5) => Srl,
                (0x20, 5) => Sra,
                (0, 6) => Or,
                (0, 7) => And,
                (1, 0) => Mul,
                (1, 1) => Mulh,
                (1, 2) => Mulhsu,
                (1, 3) => Mulhu,
                (1, 4) => Div,
                (1, 5) => Divu,
                (1, 6) => Rem,
                (1, 7) => Remu,
                _ => return Err(err("OP funct7/funct3")),
            };
            r(op)
        }
        0x0F if f3 == 0 => Ok(make(Fence, 0, 0, 0, 0, 0)),
        0x73 => {
            if w == 0x0010_0073 {
                return Ok(make(Ebreak, 0, 0, 0, 0, 0));
            }
            if w == 0x0000_0073 {
                return Err(err("ecall is not supported (docs/isa.md)"));
            }
            let csr = ((w >> 20) & 0xFFF) as i32;
            if !(CSR_FFLAGS..=CSR_FCSR).contains(&csr) {
                return Err(err("CSR other than fflags/frm/fcsr"));
            }
            let op = match f3 {
                1 => Csrrw,
                2 => Csrrs,
                3 => Csrrc,
                5 => Csrrwi,
                6 => Csrrsi,
                7 => Csrrci,
                _ => return Err(err("SYSTEM funct3")),
            };
            Ok(make(op, rd, rs1, 0, 0, csr))
        }
        0x07 if f3 == 2 => i(Flw),
        0x27 if f3 == 2 => Ok(make(Fsw, 0, rs1, rs2, 0, imm_s)),
        0x43 | 0x47 | 0x4B | 0x4F => {
            if f2 != 0 {
                return Err(err("fused multiply-add format other than S"));
            }
            rne(match opcode {
                0x43 => FmaddS,
                0x47 => FmsubS,
                0x4B => FnmsubS,
                _ => FnmaddS,
            })
        }
        0x53 => match f7 {
            0x00 => rne(FaddS),
            0x04 => rne(FsubS),
            0x08 => rne(FmulS),
            0x0C => rne(FdivS),
            0x2C if rs2 == 0 => rne(FsqrtS),
            0x10 => match f3 {
                0 => r(FsgnjS),
                1 => r(FsgnjnS),
                2 => r(FsgnjxS),
                _ => Err(err("fsgnj funct3")),
            },
            0x14 => match f3 {
                0 => r(FminS),
                1 => r(FmaxS),
                _ => Err(err("fmin/fmax funct3")),
            },
            0x60 if rs2 <= 1 => {
                if f3 == 5 || f3 == 6 {
                    return Err(err("invalid rounding mode"));
                }
                let op = if rs2 == 0 { FcvtWS } else { FcvtWuS };
                Ok(make(op, rd, rs1, 0, 0, f3 as i32))
            }
            0x70 if rs2 == 0 && f3 == 0 => r(FmvXW),
            0x70 if rs2 == 0 && f3 == 1 => r(FclassS),
            0x50 => match f3 {
                2 => r(FeqS),
                1 => r(FltS),
                0 => r(FleS),
                _ => Err(err("compare funct3")),
            },
            0x68 if rs2 == 0 => rne(FcvtSW),
            0x68 if rs2 == 1 => rne(FcvtSWu),
            0x78 if rs2 == 0 && f3 == 0 => r(FmvWX),
            _ => Err(err("OP-FP funct7 (only single precision is supported)")),
        },
        OPCODE_CUSTOM0 | OPCODE_CUSTOM1 | OPCODE_CUSTOM2 | OPCODE_CUSTOM3 => {
            match super::isa::lookup(w) {
                Some((e, imm)) => {
                    let used = |k: usize, r: u8| if e.regs[k] { r } else { 0 };
                    // rt.ldp names no register but P[k]: k & 31 in rd, k >> 5 in rs2.
                    let (rd, rs2) = if e.op == Op::RtLdp {
                        let k = super::isa::pipe_index(e, w);
                        (k & 31, k >> 5)
                    } else {
                        (used(0, rd), used(2, rs2))
                    };
                    Ok(make(e.op, rd, used(1, rs1), rs2, used(3, rs3), imm))
                }
                None => Err(err("custom opcode funct3/funct2/funct7")),
            }
        }
        _ => Err(err(
            "unknown opcode (compressed, A, D and other extensions are not supported)",
        )),
    }
}
