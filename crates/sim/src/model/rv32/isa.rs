//! The one table of the ray-tracing instructions' encodings (`docs/isa.md`, "Encoding").
//!
//! The decoder reads it ([`mod@super::decode`]); `kernels/rt.h` emits the same fields with
//! `.insn`, and `docs/isa.md` lists them: the test `rt_table_agrees_with_rt_h_and_isa_md`
//! checks that all three say the same. Adding an instruction is one row here, one `.insn`
//! in `rt.h`, one row in `isa.md`, and its [`Op`] in the executor (`docs/extending.md`).

/// The operation of a decoded instruction. Operands are in [`Instr`](super::decode::Instr).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
#[allow(missing_docs)] // the RISC-V mnemonics, one variant each
pub enum Op {
    Lui,
    Auipc,
    Jal,
    Jalr,
    Beq,
    Bne,
    Blt,
    Bge,
    Bltu,
    Bgeu,
    Lb,
    Lh,
    Lw,
    Lbu,
    Lhu,
    Sb,
    Sh,
    Sw,
    Addi,
    Slti,
    Sltiu,
    Xori,
    Ori,
    Andi,
    Slli,
    Srli,
    Srai,
    Add,
    Sub,
    Sll,
    Slt,
    Sltu,
    Xor,
    Srl,
    Sra,
    Or,
    And,
    Mul,
    Mulh,
    Mulhsu,
    Mulhu,
    Div,
    Divu,
    Rem,
    Remu,
    /// `fence` (a no-op: one thread, in-order memory).
    Fence,
    /// `ebreak`: ends the thread.
    Ebreak,
    /// `csrrw` (`imm` = CSR number).
    Csrrw,
    Csrrs,
    Csrrc,
    /// `csrrwi` (`rs1` = the 5-bit immediate).
    Csrrwi,
    Csrrsi,
    Csrrci,
    Flw,
    Fsw,
    FmaddS,
    FmsubS,
    FnmsubS,
    FnmaddS,
    FaddS,
    FsubS,
    FmulS,
    FdivS,
    FsqrtS,
    FsgnjS,
    FsgnjnS,
    FsgnjxS,
    FminS,
    FmaxS,
    /// `fcvt.w.s` (`imm` = rounding mode).
    FcvtWS,
    /// `fcvt.wu.s` (`imm` = rounding mode).
    FcvtWuS,
    FmvXW,
    FeqS,
    FltS,
    FleS,
    FclassS,
    FcvtSW,
    FcvtSWu,
    FmvWX,
    /// `rt.setorg`: `R.o = (f[rs1], f[rs2], f[rs3])`.
    RtSetOrg,
    /// `rt.setinv`: `R.inv = (f[rs1], f[rs2], f[rs3])`.
    RtSetInv,
    /// `rt.setshear`: `R.shear = (f[rs1], f[rs2], f[rs3])`.
    RtSetShear,
    /// `rt.setk`: `R.k` from `x[rs1] = kx | ky << 2 | kz << 4`.
    RtSetK,
    /// `rt.rcp`: `f[rd] = 1 / f[rs1]`.
    RtRcp,
    /// `rt.atominc`: `x[rd] = G[x[rs1]]++`.
    RtAtomInc,
    /// `rt.srand`: the random key `K = (x[rs1], x[rs2], x[rs3])` (pixel x, y, sample).
    RtSRand,
    /// `rt.rand` (`imm` = dim): `f[rd]` = the renderer's random number of
    /// `[K, x[rs1], x[rs2], dim]` (bounce, seed) in `[0, 1)`.
    RtRand,
    /// `rt.box`: `f[rd]` = entry distance or NaN; the exit distance to `B.exit`.
    RtBox,
    /// `rt.boxn` (`imm` = N = 2, 4, 8): `x[rd]` = hit mask, entries to `B`.
    RtBoxN,
    /// `rt.boxget` (`imm` = k): `f[rd] = B[k]` (k = 0–7), `B.exit` (k = 8).
    RtBoxGet,
    /// `rt.tri`: `f[rd]` = `t` or NaN.
    RtTri,
    /// `rt.dst`: `x[rd] = code | offset << 2`, the rest to `D`.
    RtDst,
    /// `rt.dstget` (`imm` = field 0, 1, 2, 3).
    RtDstGet,
    /// `rt.ldp` / `rt.ldph`: `P[k] = mem[x[rs1] + imm]`, `k = rd + 32 · rs2` (0–47; the
    /// two fields name no register).
    RtLdp,
    /// `rt.boxp`: `rt.box` on the box in `P[0..6]`.
    RtBoxP,
    /// `rt.boxnp` (`imm` = N): `rt.boxn` on the N boxes in `P[0..6N]`.
    RtBoxNP,
    /// `rt.trip`: `rt.tri` on the triangle in `P[0..9]`.
    RtTriP,
    /// `rt.dstp`: `rt.dst` on the node in `P[0..3]`.
    RtDstP,
    /// `rt.qboxn`: the 8 dequantized child boxes of the 80-byte CWBVH node at `x[rs1]`,
    /// `x[rd]` = hit mask, entries to `B`.
    RtQBoxN,
    /// `rt.qboxnp`: `rt.qboxn` on the node in `P[0..20]`.
    RtQBoxNP,
    /// `rt.dstqp`: the DST-Q record named by `x[rs1]` (cluster word address << 9 | bit
    /// position; frame in `P[32..36]`, the record's words in `P[36..39]`): `x[rd]` = the next
    /// record's name or the run's index entry, the rest (code included) to `D`.
    RtDstQP,
    /// A word that does not decode (`imm` = the word); executing it is an error.
    Illegal,
}

/// Opcode of the custom-0 space (`rt.set*`, `rt.rcp`, `rt.atominc`, `rt.srand`, `rt.rand`).
pub const OPCODE_CUSTOM0: u32 = 0x0B;
/// Opcode of the custom-1 space (`rt.box`, `rt.boxn`, `rt.boxget`, `rt.tri`, `rt.dst`,
/// `rt.dstget`, `rt.qboxn`).
pub const OPCODE_CUSTOM1: u32 = 0x2B;
/// Opcode of the custom-2 space (`rt.ldp`, `rt.ldph`: loads into the pipeline input
/// registers `P`).
pub const OPCODE_CUSTOM2: u32 = 0x5B;
/// Opcode of the custom-3 space (`rt.boxp`, `rt.boxnp`, `rt.trip`, `rt.dstp`, `rt.qboxnp`:
/// the register forms, reading their node words from `P`; `funct3` and `funct2` as the
/// memory forms'; and `rt.dstqp`, which has no memory form).
pub const OPCODE_CUSTOM3: u32 = 0x7B;
/// Words of the pipeline input registers `P` (the largest reader: `rt.boxnp` with 8 boxes).
pub const PIPE_INPUT_WORDS: usize = 48;

/// The instruction format (`.insn r4` or `.insn r`) and the function field checked beside
/// `funct3`, with its largest valid value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// R4: `rs3` in bits 27–31, `funct2` in bits 25–26, at most this value.
    R4 {
        /// Largest valid `funct2`.
        funct2_max: u32,
    },
    /// R: `funct7` in bits 25–31, at most this value.
    R {
        /// Largest valid `funct7`.
        funct7_max: u32,
    },
    /// I (`.insn i`, a load's form): the 12-bit signed byte offset in bits 20–31; the `rd`
    /// field names no register but `P[p_base + rd]`, `rd` at most `rd_max`.
    I {
        /// Largest valid `rd` field.
        rd_max: u32,
        /// The first `P` word the row reaches.
        p_base: u32,
    },
}

/// What the function field (`funct2` or `funct7`) becomes in the decoded immediate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Imm {
    /// Nothing (the field must be 0).
    None,
    /// The box count `N = 2 << funct2` of `rt.boxn`.
    BoxCount,
    /// The field itself (the latch index of `rt.boxget`, `rt.dstget`).
    Field,
    /// The sign-extended 12-bit byte offset of the I format (`rt.ldp`).
    Offset,
}

/// One ray-tracing instruction's encoding and operands.
#[derive(Clone, Copy, Debug)]
pub struct RtEncoding {
    /// Mnemonic, as in `docs/isa.md` (`rt.box`); `rt.h` names its function `rt_box`.
    pub mnemonic: &'static str,
    /// The decoded operation.
    pub op: Op,
    /// [`OPCODE_CUSTOM0`] … [`OPCODE_CUSTOM3`].
    pub opcode: u32,
    /// `funct3`.
    pub funct3: u32,
    /// Format and function field.
    pub format: Format,
    /// Registers read and written: `rd`, `rs1`, `rs2`, `rs3` (an unused one decodes as 0).
    pub regs: [bool; 4],
    /// The decoded immediate.
    pub imm: Imm,
}

const fn row(
    mnemonic: &'static str,
    op: Op,
    opcode: u32,
    funct3: u32,
    format: Format,
    regs: [bool; 4],
    imm: Imm,
) -> RtEncoding {
    RtEncoding {
        mnemonic,
        op,
        opcode,
        funct3,
        format,
        regs,
        imm,
    }
}

const R4: Format = Format::R4 { funct2_max: 0 };
const R: Format = Format::R { funct7_max: 0 };
/// `rs1`, `rs2`, `rs3` read; no `rd`.
const SET3: [bool; 4] = [false, true, true, true];
/// `rd` written from `rs1`.
const UNARY: [bool; 4] = [true, true, false, false];
/// `rd` from a memory operand at `rs1` and the interval `rs2`, `rs3`.
const MEM: [bool; 4] = [true, true, true, true];
/// `rd` only (a latch read).
const GET: [bool; 4] = [true, false, false, false];
/// `rd` from `P` and the interval `rs2`, `rs3` (a register form).
const PIPE: [bool; 4] = [true, false, true, true];
/// A load into `P`: the address register `rs1` (the `rd` field is the `P` index).
const LDP: [bool; 4] = [false, true, false, false];

/// Every ray-tracing instruction (Lin et al. 2020, §2.3, §3; `docs/isa.md`), and the
/// quantized structures' (`rt.qboxn`, `rt.qboxnp`, `rt.dstqp`; beyond the paper).
pub const RT_INSTRUCTIONS: [RtEncoding; 23] = [
    row(
        "rt.setorg",
        Op::RtSetOrg,
        OPCODE_CUSTOM0,
        0,
        R4,
        SET3,
        Imm::None,
    ),
    row(
        "rt.setinv",
        Op::RtSetInv,
        OPCODE_CUSTOM0,
        1,
        R4,
        SET3,
        Imm::None,
    ),
    row(
        "rt.setshear",
        Op::RtSetShear,
        OPCODE_CUSTOM0,
        2,
        R4,
        SET3,
        Imm::None,
    ),
    row(
        "rt.setk",
        Op::RtSetK,
        OPCODE_CUSTOM0,
        3,
        R,
        [false, true, false, false],
        Imm::None,
    ),
    row("rt.rcp", Op::RtRcp, OPCODE_CUSTOM0, 4, R, UNARY, Imm::None),
    row(
        "rt.atominc",
        Op::RtAtomInc,
        OPCODE_CUSTOM0,
        5,
        R,
        UNARY,
        Imm::None,
    ),
    row(
        "rt.srand",
        Op::RtSRand,
        OPCODE_CUSTOM0,
        6,
        R4,
        SET3,
        Imm::None,
    ),
    row(
        "rt.rand",
        Op::RtRand,
        OPCODE_CUSTOM0,
        7,
        Format::R { funct7_max: 127 },
        [true, true, true, false],
        Imm::Field,
    ),
    row("rt.box", Op::RtBox, OPCODE_CUSTOM1, 0, R4, MEM, Imm::None),
    row(
        "rt.boxn",
        Op::RtBoxN,
        OPCODE_CUSTOM1,
        1,
        Format::R4 { funct2_max: 2 },
        MEM,
        Imm::BoxCount,
    ),
    row(
        "rt.boxget",
        Op::RtBoxGet,
        OPCODE_CUSTOM1,
        2,
        Format::R { funct7_max: 8 },
        GET,
        Imm::Field,
    ),
    row("rt.tri", Op::RtTri, OPCODE_CUSTOM1, 3, R4, MEM, Imm::None),
    row("rt.dst", Op::RtDst, OPCODE_CUSTOM1, 4, R4, MEM, Imm::None),
    row(
        "rt.dstget",
        Op::RtDstGet,
        OPCODE_CUSTOM1,
        5,
        Format::R { funct7_max: 3 },
        GET,
        Imm::Field,
    ),
    row(
        "rt.ldp",
        Op::RtLdp,
        OPCODE_CUSTOM2,
        0,
        Format::I {
            rd_max: 31,
            p_base: 0,
        },
        LDP,
        Imm::Offset,
    ),
    row(
        "rt.ldph",
        Op::RtLdp,
        OPCODE_CUSTOM2,
        1,
        Format::I {
            rd_max: PIPE_INPUT_WORDS as u32 - 33,
            p_base: 32,
        },
        LDP,
        Imm::Offset,
    ),
    row(
        "rt.boxp",
        Op::RtBoxP,
        OPCODE_CUSTOM3,
        0,
        R4,
        PIPE,
        Imm::None,
    ),
    row(
        "rt.boxnp",
        Op::RtBoxNP,
        OPCODE_CUSTOM3,
        1,
        Format::R4 { funct2_max: 2 },
        PIPE,
        Imm::BoxCount,
    ),
    row(
        "rt.trip",
        Op::RtTriP,
        OPCODE_CUSTOM3,
        3,
        R4,
        PIPE,
        Imm::None,
    ),
    row(
        "rt.dstp",
        Op::RtDstP,
        OPCODE_CUSTOM3,
        4,
        R4,
        PIPE,
        Imm::None,
    ),
    row(
        "rt.qboxn",
        Op::RtQBoxN,
        OPCODE_CUSTOM1,
        6,
        R4,
        MEM,
        Imm::None,
    ),
    row(
        "rt.qboxnp",
        Op::RtQBoxNP,
        OPCODE_CUSTOM3,
        6,
        R4,
        PIPE,
        Imm::None,
    ),
    row(
        "rt.dstqp",
        Op::RtDstQP,
        OPCODE_CUSTOM3,
        7,
        R4,
        MEM,
        Imm::None,
    ),
];

/// The `P` index an [`Format::I`] word `w` of row `e` loads (`p_base + rd`); 0 for other rows.
pub fn pipe_index(e: &RtEncoding, w: u32) -> u8 {
    match e.format {
        Format::I { p_base, .. } => (p_base + ((w >> 7) & 31)) as u8,
        _ => 0,
    }
}

/// The table row of the custom instruction word `w`, with its decoded immediate; `None`
/// when its opcode, `funct3` or function field names no instruction.
pub fn lookup(w: u32) -> Option<(&'static RtEncoding, i32)> {
    let (opcode, f3) = (w & 0x7F, (w >> 12) & 7);
    let e = RT_INSTRUCTIONS
        .iter()
        .find(|e| e.opcode == opcode && e.funct3 == f3)?;
    let field = match e.format {
        Format::R4 { funct2_max } => Some((w >> 25) & 3).filter(|&f| f <= funct2_max),
        Format::R { funct7_max } => Some(w >> 25).filter(|&f| f <= funct7_max),
        Format::I { rd_max, .. } => Some((w >> 7) & 31).filter(|&f| f <= rd_max),
    }?;
    let imm = match e.imm {
        Imm::None => 0,
        Imm::BoxCount => 2 << field,
        Imm::Field => field as i32,
        Imm::Offset => w as i32 >> 20,
    };
    Some((e, imm))
}
