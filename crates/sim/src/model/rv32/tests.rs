//! Unit tests of the decoder and executor: per-opcode semantics on hand-assembled words,
//! the edge cases of M and F, decode errors, memory faults, and the kernels of
//! `kernels/build` loading and decoding.

use super::*;
use dualsplit_accel::MemoryImage;

/// Encoders for hand-assembled words (RISC-V unprivileged spec, ch. 24 tables).
pub(crate) mod asm {
    /// R type.
    pub fn r(op: u32, f3: u32, f7: u32, rd: u32, rs1: u32, rs2: u32) -> u32 {
        (f7 << 25) | (rs2 << 20) | (rs1 << 15) | (f3 << 12) | (rd << 7) | op
    }
    /// R4 type.
    pub fn r4(op: u32, f3: u32, f2: u32, rd: u32, rs1: u32, rs2: u32, rs3: u32) -> u32 {
        (rs3 << 27) | (f2 << 25) | (rs2 << 20) | (rs1 << 15) | (f3 << 12) | (rd << 7) | op
    }
    /// I type.
    pub fn i(op: u32, f3: u32, rd: u32, rs1: u32, imm: i32) -> u32 {
        ((imm as u32 & 0xFFF) << 20) | (rs1 << 15) | (f3 << 12) | (rd << 7) | op
    }
    /// S type.
    pub fn s(op: u32, f3: u32, rs1: u32, rs2: u32, imm: i32) -> u32 {
        let u = imm as u32;
        (((u >> 5) & 0x7F) << 25) | (rs2 << 20) | (rs1 << 15) | (f3 << 12) | ((u & 31) << 7) | op
    }
    /// B type.
    pub fn b(f3: u32, rs1: u32, rs2: u32, off: i32) -> u32 {
        let o = off as u32;
        (((o >> 12) & 1) << 31)
            | (((o >> 5) & 0x3F) << 25)
            | (rs2 << 20)
            | (rs1 << 15)
            | (f3 << 12)
            | (((o >> 1) & 0xF) << 8)
            | (((o >> 11) & 1) << 7)
            | 0x63
    }
    /// J type (`jal`).
    pub fn jal(rd: u32, off: i32) -> u32 {
        let o = off as u32;
        (((o >> 20) & 1) << 31)
            | (((o >> 1) & 0x3FF) << 21)
            | (((o >> 11) & 1) << 20)
            | (o & 0xFF000)
            | (rd << 7)
            | 0x6F
    }
    /// `lui rd, imm20 << 12`.
    pub fn lui(rd: u32, imm: u32) -> u32 {
        (imm & 0xFFFF_F000) | (rd << 7) | 0x37
    }
    /// `auipc`.
    pub fn auipc(rd: u32, imm: u32) -> u32 {
        (imm & 0xFFFF_F000) | (rd << 7) | 0x17
    }
    /// `addi`.
    pub fn addi(rd: u32, rs1: u32, imm: i32) -> u32 {
        i(0x13, 0, rd, rs1, imm)
    }
    /// `ebreak`.
    pub const EBREAK: u32 = 0x0010_0073;
    /// OP-FP with funct7 and rm/funct3.
    pub fn fp(f7: u32, f3: u32, rd: u32, rs1: u32, rs2: u32) -> u32 {
        r(0x53, f3, f7, rd, rs1, rs2)
    }
}

use asm::*;

const BASE: u32 = PROGRAM_BASE;

/// Runs `words` (an `ebreak` appended) on a fresh hart whose registers are first set by
/// `init`; returns the hart.
fn run_with(words: &[u32], init: impl FnOnce(&mut Hart)) -> Hart {
    let mut w = words.to_vec();
    w.push(EBREAK);
    let prog = Program::from_words(BASE, &w);
    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 64);
    let mut hart = Hart::new(&prog, 256);
    init(&mut hart);
    run_to_halt(&mut hart, &prog, &mut mem, 1000).unwrap();
    hart
}

#[test]
fn rt_rand_is_the_renderers_random_number_of_the_key_bounce_seed_and_dim() {
    for (x, y, sample, bounce, seed, dim) in [
        (0, 0, 0, 0, 0, 0),
        (17, 300, 3, 9, 12345, 1),
        (1023, 1023, 63, 11, u32::MAX, 127),
    ] {
        // rt.srand x1, x2, x3; f4 = rt.rand(dim) x5, x6.
        let h = run_with(
            &[r4(0x0B, 6, 0, 0, 1, 2, 3), r(0x0B, 7, dim, 4, 5, 6)],
            |h| {
                (h.x[1], h.x[2], h.x[3]) = (x, y, sample);
                (h.x[5], h.x[6]) = (bounce, seed);
            },
        );
        assert_eq!(h.rand_key, [x, y, sample]);
        // crates/render/src/job.rs `rand`: the top 24 bits of the hash over 2^24.
        let hash = dualsplit_geometry::hash_u32s(&[x, y, sample, bounce, seed, dim]);
        let want = (hash >> 8) as f32 * (1.0 / 16_777_216.0);
        assert_eq!(
            h.f[4],
            want.to_bits(),
            "{x} {y} {sample} {bounce} {seed} {dim}"
        );
        assert!((0.0..1.0).contains(&f32::from_bits(h.f[4])));
    }
    // Another key gives another number; the key starts at 0.
    let a = run_with(&[r(0x0B, 7, 0, 4, 5, 6)], |_| {}).f[4];
    let b = run_with(&[r4(0x0B, 6, 0, 0, 1, 0, 0), r(0x0B, 7, 0, 4, 5, 6)], |h| {
        h.x[1] = 1
    })
    .f[4];
    assert_ne!(a, b);
    assert_eq!(a, hart::rt_rand([0; 3], 0, 0, 0));
}

/// One R-type integer op on `a`, `b` (x1 = a, x2 = b, result in x3).
fn int_op(f3: u32, f7: u32, a: u32, b: u32) -> u32 {
    run_with(&[r(0x33, f3, f7, 3, 1, 2)], |h| {
        h.x[1] = a;
        h.x[2] = b;
    })
    .x[3]
}

/// One I-type op with immediate `imm` on `a` (x1), result in x3.
fn imm_op(f3: u32, a: u32, imm: i32) -> u32 {
    run_with(&[i(0x13, f3, 3, 1, imm)], |h| h.x[1] = a).x[3]
}

/// One OP-FP op on f1 = a, f2 = b; result in x3 (`int_rd`) or f3.
fn fp_op(word: u32, a: f32, b: f32, int_rd: bool) -> u32 {
    let h = run_with(&[word], |h| {
        h.f[1] = a.to_bits();
        h.f[2] = b.to_bits();
    });
    if int_rd { h.x[3] } else { h.f[3] }
}

fn fbin(f7: u32, f3: u32, a: f32, b: f32) -> u32 {
    fp_op(fp(f7, f3, 3, 1, 2), a, b, false)
}

#[test]
fn rv32i_alu() {
    let m = |v: i32| v as u32;
    assert_eq!(int_op(0, 0, 5, 7), 12); // add
    assert_eq!(int_op(0, 0, u32::MAX, 1), 0); // add wraps
    assert_eq!(int_op(0, 0x20, 5, 7), m(-2)); // sub
    assert_eq!(int_op(1, 0, 1, 33), 2); // sll uses the low 5 bits
    assert_eq!(int_op(2, 0, m(-1), 0), 1); // slt
    assert_eq!(int_op(3, 0, m(-1), 0), 0); // sltu
    assert_eq!(int_op(4, 0, 0b1100, 0b1010), 0b0110); // xor
    assert_eq!(int_op(5, 0, 0x8000_0000, 31), 1); // srl
    assert_eq!(int_op(5, 0x20, 0x8000_0000, 31), u32::MAX); // sra
    assert_eq!(int_op(6, 0, 0b1100, 0b1010), 0b1110); // or
    assert_eq!(int_op(7, 0, 0b1100, 0b1010), 0b1000); // and
    assert_eq!(imm_op(0, 10, -11), u32::MAX); // addi
    assert_eq!(imm_op(2, m(-5), -4), 1); // slti
    assert_eq!(imm_op(3, 5, -1), 1); // sltiu: imm sign-extended then unsigned
    assert_eq!(imm_op(4, 0xFF, -1), 0xFFFF_FF00); // xori
    assert_eq!(imm_op(6, 0xF0, 0x0F), 0xFF); // ori
    assert_eq!(imm_op(7, 0xFFFF, 0x7F0), 0x7F0); // andi
    assert_eq!(imm_op(1, 1, 31), 0x8000_0000); // slli
    assert_eq!(imm_op(5, 0x8000_0000, 4), 0x0800_0000); // srli
    assert_eq!(imm_op(5, 0x8000_0000, 4 | 0x400), 0xF800_0000); // srai
    // lui, auipc; x0 stays 0
    let h = run_with(
        &[lui(1, 0xABCDE000), auipc(2, 0x1000), addi(0, 0, 5)],
        |_| {},
    );
    assert_eq!(h.x[1], 0xABCDE000);
    assert_eq!(h.x[2], BASE + 4 + 0x1000);
    assert_eq!(h.x[0], 0);
}

#[test]
fn rv32m_edge_cases() {
    let m = |v: i32| v as u32;
    let min = 0x8000_0000u32;
    assert_eq!(int_op(0, 1, m(-3), 7), m(-21)); // mul
    assert_eq!(int_op(1, 1, min, min), 0x4000_0000); // mulh
    assert_eq!(int_op(1, 1, m(-1), m(-1)), 0);
    assert_eq!(int_op(2, 1, m(-1), u32::MAX), u32::MAX); // mulhsu: -1 * (2^32-1)
    assert_eq!(int_op(3, 1, u32::MAX, u32::MAX), 0xFFFF_FFFE); // mulhu
    assert_eq!(int_op(4, 1, m(-7), 2), m(-3)); // div truncates
    assert_eq!(int_op(4, 1, 7, 0), u32::MAX); // div by zero
    assert_eq!(int_op(4, 1, min, m(-1)), min); // overflow
    assert_eq!(int_op(5, 1, 7, 0), u32::MAX); // divu by zero
    assert_eq!(int_op(5, 1, u32::MAX, 2), 0x7FFF_FFFF);
    assert_eq!(int_op(6, 1, m(-7), 2), m(-1)); // rem: sign of the dividend
    assert_eq!(int_op(6, 1, 7, 0), 7); // rem by zero
    assert_eq!(int_op(6, 1, min, m(-1)), 0); // overflow
    assert_eq!(int_op(7, 1, 7, 0), 7); // remu by zero
    assert_eq!(int_op(7, 1, u32::MAX, 10), 5);
}

#[test]
fn branches_and_jumps() {
    // For each branch: x3 = 1 if taken (skips the addi x3, x0, 2).
    let cases: [(u32, u32, u32, bool); 12] = [
        (0, 5, 5, true),
        (0, 5, 6, false),
        (1, 5, 6, true),
        (1, 5, 5, false),
        (4, (-1i32) as u32, 0, true),
        (4, 0, (-1i32) as u32, false),
        (5, 0, 0, true),
        (5, (-1i32) as u32, 0, false),
        (6, 0, (-1i32) as u32, true),
        (6, (-1i32) as u32, 0, false),
        (7, (-1i32) as u32, 0, true),
        (7, 0, 1, false),
    ];
    for (f3, a, bv, taken) in cases {
        let h = run_with(&[b(f3, 1, 2, 8), addi(3, 0, 2), addi(4, 0, 1)], |h| {
            h.x[1] = a;
            h.x[2] = bv;
        });
        assert_eq!(h.x[3] == 0, taken, "funct3 {f3} a {a:#x} b {bv:#x}");
        assert_eq!(h.x[4], 1);
    }
    // jal links pc + 4 and jumps; jalr clears bit 0.
    let h = run_with(
        &[jal(1, 8), addi(3, 0, 9), i(0x67, 0, 5, 6, 1), addi(3, 0, 9)],
        |h| {
            h.x[6] = BASE + 15 // jalr x5, 1(x6) -> BASE + 16 (the ebreak)
        },
    );
    assert_eq!(h.x[1], BASE + 4);
    assert_eq!(h.x[5], BASE + 12);
    assert_eq!(h.x[3], 0);
    // jalr with rd = rs1 jumps to the old value.
    let h = run_with(&[i(0x67, 0, 6, 6, 8), addi(3, 0, 9), addi(3, 0, 9)], |h| {
        h.x[6] = BASE + 4 // -> BASE + 12 (the ebreak)
    });
    assert_eq!((h.x[6], h.x[3]), (BASE + 4, 0));
    // Retired records a taken branch.
    let prog = Program::from_words(BASE, &[b(0, 0, 0, 8), EBREAK, EBREAK]);
    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 0);
    let mut h = Hart::new(&prog, 0);
    let r = h.step(&prog, &mut mem).unwrap();
    assert!(r.taken);
    assert_eq!(r.fu(), FuClass::Branch);
    assert_eq!(h.pc, BASE + 8);
}

#[test]
fn loads_and_stores() {
    let ls = LOCAL_STORE_ADDR;
    // x1 = local store base; sw/sh/sb then loads with sign/zero extension.
    let h = run_with(
        &[
            s(0x23, 2, 1, 2, 0),  // sw x2, 0(x1)
            s(0x23, 1, 1, 2, 4),  // sh x2, 4(x1)
            s(0x23, 0, 1, 2, 7),  // sb x2, 7(x1)
            i(0x03, 2, 10, 1, 0), // lw
            i(0x03, 0, 11, 1, 0), // lb  (0x80 -> -128)
            i(0x03, 4, 12, 1, 0), // lbu
            i(0x03, 1, 13, 1, 0), // lh  (0xFF80)
            i(0x03, 5, 14, 1, 0), // lhu
            i(0x03, 2, 15, 1, 4), // lw of the half and byte stores
            i(0x07, 2, 1, 1, 0),  // flw f1
            s(0x27, 2, 1, 1, 8),  // fsw f1, 8(x1)
            i(0x03, 2, 16, 1, 8), // lw
        ],
        |h| {
            h.x[1] = ls;
            h.x[2] = 0x1234_FF80;
        },
    );
    assert_eq!(h.x[10], 0x1234_FF80);
    assert_eq!(h.x[11], (-128i32) as u32);
    assert_eq!(h.x[12], 0x80);
    assert_eq!(h.x[13], 0xFFFF_FF80);
    assert_eq!(h.x[14], 0xFF80);
    assert_eq!(h.x[15], 0x8000_FF80);
    assert_eq!(h.f[1], 0x1234_FF80);
    assert_eq!(h.x[16], 0x1234_FF80);
}

#[test]
fn retired_records_local_accesses_csr_and_fence() {
    let ls = LOCAL_STORE_ADDR;
    let words = [
        s(0x23, 2, 2, 1, -4),    // sw x1, -4(sp): local store
        i(0x03, 2, 3, 2, -4),    // lw x3, -4(sp)
        i(0x73, 5, 4, 0, 1),     // csrrwi x4, fflags, 0
        i(0x73, 6, 5, 0, 2),     // csrrsi x5, frm, 0 (no write)
        i(0x73, 3, 6, 7, 3),     // csrrc x6, fcsr, x7
        i(0x0F, 0, 0, 0, 0x0FF), // fence
        EBREAK,
    ];
    let prog = Program::from_words(BASE, &words);
    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 0);
    let mut h = Hart::new(&prog, 64);
    assert_eq!(h.x[2], ls + 64);
    h.x[1] = 0xDEAD_BEEF;
    h.x[4] = 1;
    h.x[5] = 1;
    h.x[6] = 1;
    let r = h.step(&prog, &mut mem).unwrap();
    assert_eq!(r.fu(), FuClass::LocalStore);
    assert_eq!(
        r.mem,
        MemAccess {
            addr: ls + 60,
            words: 1,
            store: true,
            local: true
        }
    );
    assert_eq!(r.info.src, [Reg::x(2), Reg::x(1), Reg::NONE]);
    let r = h.step(&prog, &mut mem).unwrap();
    assert_eq!(r.fu(), FuClass::LocalLoad);
    assert_eq!(r.info.dst, Reg::x(3));
    assert_eq!(h.x[3], 0xDEAD_BEEF);
    for _ in 0..4 {
        let r = h.step(&prog, &mut mem).unwrap();
        assert_eq!(r.fu(), FuClass::IntAlu);
        assert!(!r.mem.is_some() && !r.taken);
    }
    assert_eq!((h.x[4], h.x[5], h.x[6]), (0, 0, 0));
    let r = h.step(&prog, &mut mem).unwrap();
    assert!(r.is_halt() && h.halted);
    assert_eq!(h.pc, BASE + 24);
}

/// The TP's executor, `Hart::exec_register` and, where it declines, `Hart::exec_access`,
/// runs every instruction as `step` does.
#[test]
fn the_tps_executor_runs_every_instruction_as_step_does() {
    let words = [
        addi(1, 0, 7),        // a register operation
        s(0x23, 2, 2, 1, -4), // sw x1, -4(sp)
        i(0x03, 2, 3, 2, -4), // lw x3, -4(sp)
        addi(4, 3, 1),
        b(1, 4, 0, 8), // bne x4, x0, +8: taken
        addi(5, 0, 1), // skipped
        lui(6, 0x1234_5000),
        EBREAK,
    ];
    let prog = Program::from_words(BASE, &words);
    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 0);
    let (mut a, mut b) = (Hart::new(&prog, 64), Hart::new(&prog, 64));
    let mut out_of_line = 0;
    for _ in 0..7 {
        let ins = *prog.fetch(b.pc).expect("in the text");
        let acc = match b.exec_register(&ins) {
            Some(_) => MemAccess::NONE,
            None => {
                out_of_line += 1;
                b.exec_access(&ins, &prog, &mut mem).unwrap()
            }
        };
        let r = a.step(&prog, &mut mem).unwrap();
        assert_eq!(acc, r.mem);
        assert_eq!((a.pc, a.x, a.f), (b.pc, b.x, b.f));
    }
    assert_eq!(out_of_line, 3, "sw, lw and ebreak");
    assert_eq!((b.x[3], b.x[4], b.x[5], b.x[6]), (7, 8, 0, 0x1234_5000));
    assert_eq!(b.pc, BASE + 28);
}

#[test]
fn memory_regions_and_faults() {
    let image = MemoryImage::default();
    let params = [1u8, 0, 0, 0, 2, 0, 0, 0];
    let words = [
        lui(1, PARAMS_ADDR),
        i(0x03, 2, 2, 1, 4), // lw x2, 4(params)
        lui(3, FRAME_BUFFER_ADDR),
        s(0x23, 2, 3, 2, 8), // sw x2, 8(frame)
        EBREAK,
    ];
    let prog = Program::from_words(BASE, &words);
    let mut mem = FrameMemory::new(&image, &params, 16);
    let mut h = Hart::new(&prog, 64);
    let r = h.step(&prog, &mut mem).unwrap();
    assert!(!r.mem.is_some());
    let r = h.step(&prog, &mut mem).unwrap();
    assert_eq!(r.fu(), FuClass::Load);
    assert_eq!(
        r.mem,
        MemAccess {
            addr: PARAMS_ADDR + 4,
            words: 1,
            store: false,
            local: false
        }
    );
    h.step(&prog, &mut mem).unwrap();
    let r = h.step(&prog, &mut mem).unwrap();
    assert_eq!(r.fu(), FuClass::Store);
    assert!(r.mem.store);
    assert_eq!(&mem.frame[8..12], &[2, 0, 0, 0]);

    // Faults: one instruction each, x1 = address.
    let fault = |word: u32, addr: u32| {
        let prog = Program::from_words(BASE, &[word, EBREAK]);
        let mut mem = FrameMemory::new(&image, &params, 16);
        let mut h = Hart::new(&prog, 64);
        h.x[1] = addr;
        h.step(&prog, &mut mem).unwrap_err()
    };
    let lw = i(0x03, 2, 2, 1, 0);
    let sw = s(0x23, 2, 1, 2, 0);
    let pc = BASE;
    assert_eq!(
        fault(lw, 2),
        ExecError::Misaligned {
            pc,
            addr: 2,
            bytes: 4
        }
    );
    assert_eq!(fault(lw, 0x100), ExecError::Unmapped { pc, addr: 0x100 });
    assert_eq!(
        fault(lw, PARAMS_ADDR + 8),
        ExecError::Unmapped {
            pc,
            addr: PARAMS_ADDR + 8
        }
    );
    let end = FRAME_BUFFER_ADDR + 16;
    assert_eq!(fault(sw, end), ExecError::Unmapped { pc, addr: end });
    assert_eq!(
        fault(sw, PARAMS_ADDR),
        ExecError::ReadOnly {
            pc,
            addr: PARAMS_ADDR
        }
    );
    assert_eq!(fault(sw, BASE), ExecError::ReadOnly { pc, addr: BASE });
    let top = LOCAL_STORE_ADDR + 64;
    assert_eq!(fault(sw, top), ExecError::Unmapped { pc, addr: top });
    assert_eq!(
        fault(i(0x03, 1, 2, 1, 0), LOCAL_STORE_ADDR + 1),
        ExecError::Misaligned {
            pc,
            addr: LOCAL_STORE_ADDR + 1,
            bytes: 2
        }
    );
    // The program region is readable.
    let prog = Program::from_words(BASE, &[i(0x03, 2, 2, 1, 4), EBREAK]);
    let mut mem = FrameMemory::new(&image, &params, 16);
    let mut h = Hart::new(&prog, 64);
    h.x[1] = BASE;
    h.step(&prog, &mut mem).unwrap();
    assert_eq!(h.x[2], EBREAK);
    // Fetch outside the text, illegal words.
    let prog = Program::from_words(BASE, &[jal(0, 8), 0xFFFF_FFFF]);
    let mut h = Hart::new(&prog, 0);
    h.step(&prog, &mut mem).unwrap();
    assert_eq!(
        h.step(&prog, &mut mem),
        Err(ExecError::Fetch { pc: BASE + 8 })
    );
    h.pc = BASE + 4;
    assert!(matches!(
        h.step(&prog, &mut mem),
        Err(ExecError::Illegal { pc, word: 0xFFFF_FFFF, .. }) if pc == BASE + 4
    ));
    // The image: node words then triangles.
    let tri = dualsplit_geometry::Triangle {
        v: [
            dualsplit_geometry::Vec3::new(1.0, 2.0, 3.0),
            dualsplit_geometry::Vec3::ZERO,
            dualsplit_geometry::Vec3::ZERO,
        ],
    };
    let mut image = MemoryImage::with_triangles(2, 1, vec![tri].into());
    image.words[1] = 77;
    let mut mem = FrameMemory::new(&image, &[], 0);
    assert_eq!(mem.load::<4>(4), Ok(77u32.to_le_bytes()));
    assert_eq!(mem.load::<4>(12 + 4), Ok(2.0f32.to_le_bytes()));
    assert_eq!(mem.load::<4>(12 + 36), Err(MemFault::Unmapped));
    assert_eq!(mem.store::<4>(4, [0; 4]), Err(MemFault::ReadOnly));
}

#[test]
fn float_arithmetic_and_nan() {
    let nan = f32::NAN;
    let bits = |v: f32| v.to_bits();
    assert_eq!(fbin(0x00, 0, 1.5, 2.25), bits(3.75));
    assert_eq!(fbin(0x04, 7, 1.5, 2.25), bits(-0.75));
    assert_eq!(fbin(0x08, 0, 1.5, -2.0), bits(-3.0));
    assert_eq!(fbin(0x0C, 0, 1.0, 3.0), bits(1.0 / 3.0));
    assert_eq!(fbin(0x0C, 0, 1.0, 0.0), bits(f32::INFINITY));
    // NaN results are canonical (x86 would give 0xFFC00000 for 0/0 and inf-inf).
    assert_eq!(fbin(0x0C, 0, 0.0, 0.0), CANONICAL_NAN);
    assert_eq!(
        fbin(0x00, 0, f32::INFINITY, f32::NEG_INFINITY),
        CANONICAL_NAN
    );
    assert_eq!(
        fbin(0x00, 0, f32::from_bits(0xFFC0_0001), 1.0),
        CANONICAL_NAN
    );
    let sqrt = |a: f32| fp_op(fp(0x2C, 0, 3, 1, 0), a, 0.0, false);
    assert_eq!(sqrt(2.0), bits(2.0f32.sqrt()));
    assert_eq!(sqrt(-1.0), CANONICAL_NAN);
    assert_eq!(sqrt(-0.0), bits(-0.0));
    // fmin / fmax: NaN operand ignored, both NaN canonical, -0 < +0.
    assert_eq!(fbin(0x14, 0, nan, 2.0), bits(2.0));
    assert_eq!(fbin(0x14, 0, 2.0, nan), bits(2.0));
    assert_eq!(fbin(0x14, 1, nan, -2.0), bits(-2.0));
    assert_eq!(fbin(0x14, 0, nan, nan), CANONICAL_NAN);
    assert_eq!(fbin(0x14, 0, 0.0, -0.0), bits(-0.0));
    assert_eq!(fbin(0x14, 0, -0.0, 0.0), bits(-0.0));
    assert_eq!(fbin(0x14, 1, -0.0, 0.0), bits(0.0));
    assert_eq!(fbin(0x14, 1, 0.0, -0.0), bits(0.0));
    assert_eq!(fbin(0x14, 0, 1.0, -3.0), bits(-3.0));
    assert_eq!(fbin(0x14, 1, 1.0, -3.0), bits(1.0));
    // fsgnj family.
    assert_eq!(fbin(0x10, 0, 3.0, -1.0), bits(-3.0));
    assert_eq!(fbin(0x10, 1, 3.0, -1.0), bits(3.0));
    assert_eq!(fbin(0x10, 2, -3.0, -1.0), bits(3.0));
    assert_eq!(fbin(0x10, 2, nan, -1.0), bits(nan) ^ 0x8000_0000); // no canonicalisation
    // Compares: NaN → 0.
    let cmp = |f3: u32, a: f32, b: f32| fp_op(fp(0x50, f3, 3, 1, 2), a, b, true);
    assert_eq!(cmp(2, 1.0, 1.0), 1);
    assert_eq!(cmp(2, 0.0, -0.0), 1);
    assert_eq!(cmp(2, nan, nan), 0);
    assert_eq!(cmp(1, 1.0, 2.0), 1);
    assert_eq!(cmp(1, nan, 2.0), 0);
    assert_eq!(cmp(0, 2.0, 2.0), 1);
    assert_eq!(cmp(0, 2.0, nan), 0);
}

#[test]
fn float_conversions_and_moves() {
    let cvt = |rs2: u32, rm: u32, a: f32| fp_op(fp(0x60, rm, 3, 1, rs2), a, 0.0, true);
    let m = |v: i32| v as u32;
    // fcvt.w.s: rounding modes, saturation, NaN → max.
    assert_eq!(cvt(0, 1, -2.7), m(-2)); // rtz
    assert_eq!(cvt(0, 0, 2.5), 2); // rne
    assert_eq!(cvt(0, 7, 3.5), 4); // dyn = rne
    assert_eq!(cvt(0, 2, -2.5), m(-3)); // rdn
    assert_eq!(cvt(0, 3, 2.1), 3); // rup
    assert_eq!(cvt(0, 4, 2.5), 3); // rmm
    assert_eq!(cvt(0, 1, 3e9), i32::MAX as u32);
    assert_eq!(cvt(0, 1, -3e9), i32::MIN as u32);
    assert_eq!(cvt(0, 1, f32::NEG_INFINITY), i32::MIN as u32);
    assert_eq!(cvt(0, 1, f32::NAN), i32::MAX as u32);
    assert_eq!(cvt(0, 1, -f32::NAN), i32::MAX as u32);
    // fcvt.wu.s.
    assert_eq!(cvt(1, 1, 3e9), 3_000_000_000);
    assert_eq!(cvt(1, 1, 5e9), u32::MAX);
    assert_eq!(cvt(1, 1, -1.0), 0);
    assert_eq!(cvt(1, 1, -0.5), 0);
    assert_eq!(cvt(1, 1, f32::NAN), u32::MAX);
    // int → float (RNE).
    let to_f = |rs2: u32, x: u32| run_with(&[fp(0x68, 7, 3, 1, rs2)], |h| h.x[1] = x).f[3];
    assert_eq!(to_f(0, m(-5)), (-5.0f32).to_bits());
    assert_eq!(to_f(0, 16_777_217), 16_777_216.0f32.to_bits()); // tie to even
    assert_eq!(to_f(1, u32::MAX), 4_294_967_296.0f32.to_bits());
    // fmv.x.w / fmv.w.x keep the bits (NaN payloads too).
    let h = run_with(&[fp(0x70, 0, 3, 1, 0), fp(0x78, 0, 4, 2, 0)], |h| {
        h.f[1] = 0xFFC0_1234;
        h.x[2] = 0x7F80_0001;
    });
    assert_eq!(h.x[3], 0xFFC0_1234);
    assert_eq!(h.f[4], 0x7F80_0001);
    // fclass.
    let class = |v: u32| run_with(&[fp(0x70, 1, 3, 1, 0)], |h| h.f[1] = v).x[3];
    assert_eq!(class(f32::NEG_INFINITY.to_bits()), 1 << 0);
    assert_eq!(class((-1.0f32).to_bits()), 1 << 1);
    assert_eq!(class(0x8000_0001), 1 << 2);
    assert_eq!(class(0x8000_0000), 1 << 3);
    assert_eq!(class(0), 1 << 4);
    assert_eq!(class(1), 1 << 5);
    assert_eq!(class(1.0f32.to_bits()), 1 << 6);
    assert_eq!(class(f32::INFINITY.to_bits()), 1 << 7);
    assert_eq!(class(0x7F80_0001), 1 << 8);
    assert_eq!(class(0x7FC0_0000), 1 << 9);
}

#[test]
fn fused_multiply_add_rounds_once() {
    // a*b + c where the product's rounding matters: (1 + 2^-23)(1 - 2^-23) - 1 = -2^-46.
    let a = 1.0 + f32::EPSILON;
    let b = 1.0 - f32::EPSILON;
    let c = -1.0f32;
    let fma = |op: u32| {
        run_with(&[r4(op, 0, 0, 3, 1, 2, 4)], |h| {
            h.f[1] = a.to_bits();
            h.f[2] = b.to_bits();
            h.f[4] = c.to_bits();
        })
        .f[3]
    };
    assert_eq!(fma(0x43), (-(2.0f32.powi(-46))).to_bits()); // fmadd
    assert_ne!(fma(0x43), (a * b + c).to_bits()); // two roundings give 0
    assert_eq!(fma(0x47), a.mul_add(b, -c).to_bits()); // fmsub
    assert_eq!(fma(0x4B), (-a).mul_add(b, c).to_bits()); // fnmsub
    assert_eq!(fma(0x4F), (-a).mul_add(b, -c).to_bits()); // fnmadd
}

#[test]
fn decode_errors_and_rounding_modes() {
    // Static rm other than RNE/dyn is rejected for arithmetic.
    assert!(decode(fp(0x00, 1, 3, 1, 2)).is_err());
    assert!(decode(fp(0x00, 0, 3, 1, 2)).is_ok());
    assert!(decode(fp(0x00, 7, 3, 1, 2)).is_ok());
    assert!(decode(fp(0x60, 5, 3, 1, 0)).is_err());
    // Double precision, compressed, A, ecall, unknown CSR.
    assert!(decode(fp(0x01, 0, 3, 1, 2)).is_err());
    assert!(decode(0x0000_4501).is_err());
    assert!(decode(r(0x2F, 2, 0, 1, 2, 3)).is_err());
    assert!(decode(0x0000_0073).is_err());
    assert!(decode(i(0x73, 2, 1, 0, 0xC00)).is_err());
    // Shift immediates with a bad funct7.
    assert!(decode(i(0x13, 1, 1, 1, 0x420)).is_err());
    // Custom instructions with bad function fields.
    assert!(decode(r4(0x2B, 1, 3, 1, 2, 3, 4)).is_err()); // boxn N = 16
    assert!(decode(r(0x2B, 2, 9, 1, 0, 0)).is_err()); // boxget k = 9
    assert!(decode(r(0x2B, 5, 4, 1, 0, 0)).is_err()); // dstget field 4
    assert!(decode(r4(0x0B, 6, 1, 0, 1, 2, 3)).is_err()); // rt.srand funct2 = 1
    // CSRs read 0; writing frm = RNE is fine, another mode is an error.
    let prog = Program::from_words(BASE, &[i(0x73, 2, 5, 0, 2), i(0x73, 5, 0, 1, 2), EBREAK]);
    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 0);
    let mut h = Hart::new(&prog, 0);
    h.x[5] = 9;
    h.step(&prog, &mut mem).unwrap();
    assert_eq!(h.x[5], 0);
    assert_eq!(
        h.step(&prog, &mut mem),
        Err(ExecError::RoundingMode {
            pc: BASE + 4,
            rm: 1
        })
    );
}

#[test]
fn retired_info_names_registers() {
    let ins = decode(r4(0x43, 0, 0, 3, 1, 2, 4)).unwrap();
    assert_eq!(ins.info.src, [Reg::f(1), Reg::f(2), Reg::f(4)]);
    assert_eq!(ins.info.dst, Reg::f(3));
    assert_eq!(ins.info.fu, FuClass::FpFma);
    let ins = decode(r(0x33, 0, 0, 0, 0, 5)).unwrap(); // add x0, x0, x5
    assert_eq!(ins.info.src, [Reg::NONE, Reg::x(5), Reg::NONE]);
    assert_eq!(ins.info.dst, Reg::NONE);
    let ins = decode(s(0x27, 2, 1, 7, 0)).unwrap(); // fsw f7, 0(x1)
    assert_eq!(ins.info.src, [Reg::x(1), Reg::f(7), Reg::NONE]);
    assert_eq!(ins.info.fu, FuClass::Store);
    let ins = decode(r4(0x2B, 1, 2, 9, 10, 11, 12)).unwrap(); // rt.boxn 8
    assert_eq!(ins.op, Op::RtBoxN);
    assert_eq!(ins.info.fu, FuClass::BoxPipe(8));
    assert_eq!(ins.info.dst, Reg::x(9));
    assert_eq!(ins.info.src, [Reg::x(10), Reg::f(11), Reg::f(12)]);
    assert!(ins.info.latches.reads_ray() && ins.info.latches.has(Latches::WRITES_BOX));
    assert!(std::mem::size_of::<Retired>() <= 16);
}

/// Every committed kernel ELF loads and its text decodes (no illegal word is reachable
/// from the entry in straight-line order is not checked here; the kernel runs do that).
#[test]
fn committed_kernels_load() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../kernels/build");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    for e in entries {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "elf") {
            continue;
        }
        let prog = Program::from_elf(&std::fs::read(&path).unwrap())
            .unwrap_or_else(|err| panic!("{}: {err}", path.display()));
        assert_eq!(prog.entry, PROGRAM_BASE, "{}", path.display());
        assert_eq!(prog.first_illegal(), None, "{}", path.display());
    }
}

/// The ray-tracing instructions against their Rust counterparts (`RayPre::slab`,
/// `Triangle::intersect`, `dst::pipeline::step`) on random inputs.
mod custom {
    use super::*;
    use dualsplit_accel::dst::HeaderOffset;
    use dualsplit_accel::dst::pipeline::{PipelineInput, step as dst_step};
    use dualsplit_geometry::{Ray, RayPre, Triangle, Vec3};
    use proptest::prelude::*;

    /// Byte address of the triangle in the test image (after 48 box words).
    const TRI_ADDR: u32 = 48 * 4;

    /// A float that is usually ordinary, sometimes ±0, ±∞ or NaN.
    fn any_f32() -> impl Strategy<Value = f32> + Clone {
        prop_oneof![
            8 => -10.0f32..10.0,
            1 => Just(0.0f32),
            1 => Just(-0.0f32),
            1 => Just(f32::INFINITY),
            1 => Just(f32::NEG_INFINITY),
            1 => Just(f32::NAN),
        ]
    }
    /// A direction component: usually ordinary, sometimes ±0.
    fn dir_f32() -> impl Strategy<Value = f32> + Clone {
        prop_oneof![8 => -1.0f32..1.0, 1 => Just(0.0f32), 1 => Just(-0.0f32)]
    }
    fn vec3(s: impl Strategy<Value = f32> + Clone) -> impl Strategy<Value = Vec3> {
        (s.clone(), s.clone(), s).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }
    /// A box near the origin (min ≤ max usually, sometimes inverted or degenerate).
    fn any_box() -> impl Strategy<Value = (Vec3, Vec3)> {
        prop_oneof![
            6 => (vec3(-5.0f32..5.0), vec3(0.0f32..3.0)).prop_map(|(lo, ext)| (lo, lo + ext)),
            1 => (vec3(any_f32()), vec3(any_f32())),
            1 => Just((Vec3::INFINITY, Vec3::NEG_INFINITY)),
        ]
    }

    #[derive(Debug, Clone)]
    struct Case {
        origin: Vec3,
        dir: Vec3,
        boxes: Vec<(Vec3, Vec3)>,
        /// funct2 of rt.boxn: N = 2 << log2n.
        log2n: u32,
        tri: Triangle,
        t_lo: f32,
        t_hi: f32,
        node: [u32; 3],
        t_min: f32,
        t_max: f32,
    }

    fn case() -> impl Strategy<Value = Case> {
        let tri = prop_oneof![
            3 => (vec3(-3.0f32..3.0), vec3(-3.0f32..3.0), vec3(-3.0f32..3.0)),
            1 => (vec3(any_f32()), vec3(any_f32()), vec3(any_f32())),
        ];
        let node = (
            any::<u32>(),
            prop_oneof![3 => -5.0f32..5.0, 1 => any_f32()],
            prop_oneof![3 => -5.0f32..5.0, 1 => any_f32()],
        );
        (
            vec3(-4.0f32..4.0),
            vec3(dir_f32()),
            proptest::collection::vec(any_box(), 8),
            0u32..3,
            tri,
            (
                prop_oneof![3 => 0.0f32..1.0, 1 => any_f32()],
                prop_oneof![3 => 1.0f32..100.0, 1 => any_f32()],
            ),
            node,
            (
                prop_oneof![3 => 0.0f32..2.0, 1 => any_f32()],
                prop_oneof![3 => 1.0f32..100.0, 1 => any_f32()],
            ),
            proptest::bool::ANY,
        )
            .prop_map(
                |(
                    origin,
                    dir,
                    boxes,
                    log2n,
                    (a, b, c),
                    (t_lo, t_hi),
                    (w, p0, p1),
                    (t_min, t_max),
                    aim,
                )| {
                    // Half the time aim the ray at a point of the triangle, so hits are common.
                    let dir = if aim {
                        (a * 0.3 + b * 0.3 + c * 0.4) - origin
                    } else {
                        dir
                    };
                    // ... and then every other box bounds the triangle, so box hits are common.
                    let mut boxes = boxes;
                    if aim {
                        let bounds = (a.min(b).min(c) - 0.1, a.max(b).max(c) + 0.1);
                        boxes.iter_mut().step_by(2).for_each(|bx| *bx = bounds);
                    }
                    Case {
                        origin,
                        dir,
                        boxes,
                        log2n,
                        tri: Triangle { v: [a, b, c] },
                        t_lo,
                        t_hi,
                        node: [w, p0.to_bits(), p1.to_bits()],
                        t_min,
                        t_max,
                    }
                },
            )
    }

    /// The program: set R, rt.box, rt.boxn, 8 × rt.boxget, rt.boxget 8 (B.exit), rt.tri, rt.dst, 3 × rt.dstget,
    /// rt.rcp, 2 × rt.atominc.
    fn program(f2: u32) -> Program {
        let mut w = vec![
            r4(0x0B, 0, 0, 0, 1, 2, 3),    // rt.setorg f1, f2, f3
            r4(0x0B, 1, 0, 0, 4, 5, 6),    // rt.setinv f4, f5, f6
            r4(0x0B, 2, 0, 0, 7, 8, 9),    // rt.setshear f7, f8, f9
            r(0x0B, 3, 0, 0, 5, 0),        // rt.setk x5
            r4(0x2B, 0, 0, 10, 6, 11, 12), // f10 = rt.box (x6), f11, f12
            r4(0x2B, 1, f2, 7, 6, 11, 12), // x7 = rt.boxn
        ];
        w.extend((0..8).map(|k| r(0x2B, 2, k, 20 + k, 0, 0))); // f20+k = B[k]
        w.extend([
            r(0x2B, 2, 8, 19, 0, 0),       // f19 = B.exit (rt.box's, not rt.boxn's)
            r4(0x2B, 3, 0, 14, 8, 11, 12), // f14 = rt.tri (x8), f11, f12
            r4(0x2B, 4, 0, 9, 10, 28, 29), // x9 = rt.dst (x10), f28, f29
            r(0x2B, 5, 0, 15, 0, 0),       // f15 = D.t_min_out
            r(0x2B, 5, 1, 16, 0, 0),       // f16 = D.t_max_out
            r(0x2B, 5, 2, 11, 0, 0),       // x11 = D.offset_stack
            r(0x0B, 4, 0, 17, 1, 0),       // f17 = rt.rcp f1
            r(0x0B, 5, 0, 12, 0, 0),       // x12 = rt.atominc G[x0]
            r(0x0B, 5, 0, 13, 0, 0),       // x13 = rt.atominc G[x0]
            EBREAK,
        ]);
        Program::from_words(BASE, &w)
    }

    /// `program(f2)` with each memory form replaced by its `rt.ldp` loads (`rt.ldph` from
    /// `P[32]`) and the register form: the same registers and latches result.
    fn program_loads(f2: u32) -> Program {
        let ldp = |k: u32, base: u32, word: u32| {
            let (f3, rd) = if k < 32 { (0, k) } else { (1, k - 32) };
            i(0x5B, f3, rd, base, 4 * word as i32)
        };
        let n = 2u32 << f2;
        let mut w = vec![
            r4(0x0B, 0, 0, 0, 1, 2, 3),
            r4(0x0B, 1, 0, 0, 4, 5, 6),
            r4(0x0B, 2, 0, 0, 7, 8, 9),
            r(0x0B, 3, 0, 0, 5, 0),
        ];
        w.extend((0..6).map(|k| ldp(k, 6, k)));
        w.push(r4(0x7B, 0, 0, 10, 0, 11, 12)); // f10 = rt.boxp f11, f12
        w.extend((0..6 * n).map(|k| ldp(k, 6, k)));
        w.push(r4(0x7B, 1, f2, 7, 0, 11, 12)); // x7 = rt.boxnp
        w.extend((0..8).map(|k| r(0x2B, 2, k, 20 + k, 0, 0)));
        w.push(r(0x2B, 2, 8, 19, 0, 0));
        w.extend((0..9).map(|k| ldp(k, 8, k)));
        w.push(r4(0x7B, 3, 0, 14, 0, 11, 12)); // f14 = rt.trip
        w.extend((0..3).map(|k| ldp(k, 10, k)));
        w.extend([
            r4(0x7B, 4, 0, 9, 0, 28, 29), // x9 = rt.dstp f28, f29
            r(0x2B, 5, 0, 15, 0, 0),
            r(0x2B, 5, 1, 16, 0, 0),
            r(0x2B, 5, 2, 11, 0, 0),
            r(0x0B, 4, 0, 17, 1, 0),
            r(0x0B, 5, 0, 12, 0, 0),
            r(0x0B, 5, 0, 13, 0, 0),
            EBREAK,
        ]);
        Program::from_words(BASE, &w)
    }

    fn check(c: &Case) -> Result<(), TestCaseError> {
        // N = 2, 4, 8 for funct2 = 0, 1, 2.
        let n = 2usize << c.log2n;
        let pre = RayPre::new(&Ray::new(c.origin, c.dir));
        // The image: 8 boxes at word 0, the triangle after them.
        let mut image = MemoryImage::with_triangles(48, 0, vec![c.tri].into());
        for (k, (lo, hi)) in c.boxes.iter().enumerate() {
            for (j, v) in lo.to_array().into_iter().chain(hi.to_array()).enumerate() {
                image.words[6 * k + j] = v.to_bits();
            }
        }
        let prog = program(c.log2n);
        let mut mem = FrameMemory::new(&image, &[], 0);
        let mut h = Hart::new(&prog, 64);
        // The DST node in the local store.
        for (k, w) in c.node.iter().enumerate() {
            h.local[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
        }
        let f = |v: f32| v.to_bits();
        let o = pre.ray.origin;
        let [kx, ky, kz] = pre.k;
        h.f[1..10].copy_from_slice(&[
            f(o.x),
            f(o.y),
            f(o.z),
            f(pre.inv_dir.x),
            f(pre.inv_dir.y),
            f(pre.inv_dir.z),
            f(pre.shear.x),
            f(pre.shear.y),
            f(pre.shear.z),
        ]);
        h.x[5] = (kx | ky << 2 | kz << 4) as u32;
        h.x[6] = 0;
        h.x[8] = TRI_ADDR;
        h.x[10] = LOCAL_STORE_ADDR;
        h.f[11] = f(c.t_lo);
        h.f[12] = f(c.t_hi);
        h.f[28] = f(c.t_min);
        h.f[29] = f(c.t_max);
        // The load form from the same state.
        let mut hp = h.clone();
        let prog_p = program_loads(c.log2n);
        let mut mem_p = FrameMemory::new(&image, &[], 0);
        let mut retired_p = Vec::new();
        while !hp.halted {
            retired_p.push(
                hp.step(&prog_p, &mut mem_p)
                    .map_err(|e| TestCaseError::fail(e.to_string()))?,
            );
        }
        let mut retired = Vec::new();
        while !h.halted {
            retired.push(
                h.step(&prog, &mut mem)
                    .map_err(|e| TestCaseError::fail(e.to_string()))?,
            );
        }
        // R is exactly RayPre's fields.
        prop_assert_eq!(h.ray.ray.origin.to_array().map(f), o.to_array().map(f));
        prop_assert_eq!(
            h.ray.inv_dir.to_array().map(f),
            pre.inv_dir.to_array().map(f)
        );
        prop_assert_eq!(h.ray.neg, pre.neg);
        prop_assert_eq!(h.ray.k, pre.k);
        prop_assert_eq!(h.ray.shear.to_array().map(f), pre.shear.to_array().map(f));
        // rt.box, rt.boxn, rt.boxget.
        let slab = |(lo, hi): (Vec3, Vec3)| {
            let (entry, exit) = pre.slab(lo, hi, c.t_lo, c.t_hi);
            if entry <= exit {
                (true, entry.to_bits())
            } else {
                (false, CANONICAL_NAN)
            }
        };
        prop_assert_eq!(h.f[10], slab(c.boxes[0]).1);
        let exit = pre.slab(c.boxes[0].0, c.boxes[0].1, c.t_lo, c.t_hi).1;
        prop_assert_eq!(h.f[19], exit.to_bits());
        let mut mask = 0;
        for k in 0..n {
            let (hit, entry) = slab(c.boxes[k]);
            mask |= (hit as u32) << k;
            prop_assert_eq!(h.f[20 + k], entry, "B[{}]", k);
        }
        prop_assert_eq!(h.x[7], mask);
        // rt.tri.
        let t = c
            .tri
            .intersect(&pre, c.t_lo, c.t_hi)
            .map_or(CANONICAL_NAN, |hit| hit.t.to_bits());
        prop_assert_eq!(h.f[14], t);
        // rt.dst, rt.dstget.
        let out = dst_step(&PipelineInput {
            word: HeaderOffset::from_bits(c.node[0]),
            p0: f32::from_bits(c.node[1]),
            p1: f32::from_bits(c.node[2]),
            origin: o.to_array(),
            inv_dir: pre.inv_dir.to_array(),
            t_min: c.t_min,
            t_max: c.t_max,
        });
        prop_assert_eq!(h.x[9], out.code as u32 | out.offset << 2);
        prop_assert_eq!(h.f[15], out.t_min_out.to_bits());
        prop_assert_eq!(h.f[16], out.t_max_out.to_bits());
        prop_assert_eq!(h.x[11], out.offset_stack);
        // rt.rcp, rt.atominc.
        let rcp = 1.0 / o.x;
        prop_assert_eq!(
            h.f[17],
            if rcp.is_nan() {
                CANONICAL_NAN
            } else {
                rcp.to_bits()
            }
        );
        prop_assert_eq!((h.x[12], h.x[13], mem.globals[0]), (0, 1, 2));
        // The memory operands as the timing model sees them.
        let acc = |addr, words, local| MemAccess {
            addr,
            words,
            store: false,
            local,
        };
        prop_assert_eq!(retired[4].mem, acc(0, 6, false));
        prop_assert_eq!(retired[4].fu(), FuClass::BoxPipe(1));
        prop_assert_eq!(retired[5].mem, acc(0, 6 * n as u8, false));
        prop_assert_eq!(retired[5].fu(), FuClass::BoxPipe(n as u8));
        prop_assert_eq!(retired[15].mem, acc(TRI_ADDR, 9, false));
        prop_assert_eq!(retired[15].fu(), FuClass::TriPipe);
        prop_assert_eq!(retired[16].mem, acc(LOCAL_STORE_ADDR, 3, true));
        prop_assert_eq!(retired[16].fu(), FuClass::DstPipe);
        // The load form: the same registers and latches; rt.ldp is a one-word load into P,
        // the register forms read no memory.
        prop_assert_eq!(hp.x, h.x);
        prop_assert_eq!(hp.f, h.f);
        prop_assert_eq!(hp.box_latch.map(f), h.box_latch.map(f));
        prop_assert_eq!(hp.box_exit.to_bits(), h.box_exit.to_bits());
        prop_assert_eq!(hp.dst_latch.offset_stack, h.dst_latch.offset_stack);
        for r in &retired_p {
            match r.fu() {
                FuClass::Load => {
                    prop_assert_eq!(r.mem.words, 1);
                    prop_assert!(r.info.latches.has(Latches::WRITES_PIPE));
                }
                FuClass::LocalLoad => prop_assert_eq!((r.mem.words, r.mem.local), (1, true)),
                FuClass::BoxPipe(_) | FuClass::TriPipe | FuClass::DstPipe => {
                    prop_assert_eq!(r.mem, MemAccess::NONE);
                    prop_assert!(r.info.latches.has(Latches::READS_PIPE));
                }
                _ => {}
            }
        }
        prop_assert_eq!(&hp.pipe_in[..3], &c.node[..]);
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        #[test]
        fn custom_instructions_match_rust(c in case()) {
            check(&c)?;
        }
    }

    /// Hits are common enough in the random cases that the comparison means something.
    #[test]
    fn random_cases_hit() {
        use proptest::strategy::ValueTree;
        use proptest::test_runner::TestRunner;
        let mut runner = TestRunner::deterministic();
        let (mut tri_hits, mut box_hits, mut codes) = (0, 0, [0; 4]);
        for _ in 0..500 {
            let c = case().new_tree(&mut runner).unwrap().current();
            let pre = RayPre::new(&Ray::new(c.origin, c.dir));
            tri_hits += c.tri.intersect(&pre, c.t_lo, c.t_hi).is_some() as u32;
            let (en, ex) = pre.slab(c.boxes[0].0, c.boxes[0].1, c.t_lo, c.t_hi);
            box_hits += (en <= ex) as u32;
            let out = dst_step(&PipelineInput {
                word: HeaderOffset::from_bits(c.node[0]),
                p0: f32::from_bits(c.node[1]),
                p1: f32::from_bits(c.node[2]),
                origin: c.origin.to_array(),
                inv_dir: pre.inv_dir.to_array(),
                t_min: c.t_min,
                t_max: c.t_max,
            });
            codes[out.code as usize] += 1;
        }
        assert!(tri_hits > 50, "{tri_hits} triangle hits");
        assert!(box_hits > 50, "{box_hits} box hits");
        assert!(codes.iter().all(|&k| k > 20), "return codes {codes:?}");
    }

    #[test]
    fn custom_faults() {
        let image = MemoryImage::default();
        let run1 = |word: u32, init: &dyn Fn(&mut Hart)| {
            let prog = Program::from_words(BASE, &[word, EBREAK]);
            let mut mem = FrameMemory::new(&image, &[], 0);
            let mut h = Hart::new(&prog, 64);
            init(&mut h);
            h.step(&prog, &mut mem)
        };
        let pc = BASE;
        // rt.setk with an axis of 3.
        assert_eq!(
            run1(r(0x0B, 3, 0, 0, 5, 0), &|h| h.x[5] = 3),
            Err(ExecError::BadAxes { pc, value: 3 })
        );
        // rt.atominc on a missing global register.
        assert_eq!(
            run1(r(0x0B, 5, 0, 12, 5, 0), &|h| h.x[5] = 99),
            Err(ExecError::NoGlobal { pc, index: 99 })
        );
        // rt.box at a misaligned and an unmapped address.
        let bx = r4(0x2B, 0, 0, 10, 6, 11, 12);
        assert_eq!(
            run1(bx, &|h| h.x[6] = LOCAL_STORE_ADDR + 2),
            Err(ExecError::Misaligned {
                pc,
                addr: LOCAL_STORE_ADDR + 2,
                bytes: 4
            })
        );
        assert_eq!(
            run1(bx, &|h| h.x[6] = LOCAL_STORE_ADDR + 48),
            Err(ExecError::Unmapped {
                pc,
                addr: LOCAL_STORE_ADDR + 48
            })
        );
        assert_eq!(
            run1(bx, &|h| h.x[6] = 0),
            Err(ExecError::Unmapped { pc, addr: 0 })
        );
    }
}

/// Random words never make the decoder or the executor panic: every outcome is an
/// instruction or a typed error.
mod fuzz {
    use super::*;
    use proptest::prelude::*;

    /// Random words, biased toward the opcodes we decode so that execution gets going.
    fn word() -> impl Strategy<Value = u32> {
        let opcodes = prop::sample::select(vec![
            0x37u32, 0x17, 0x6F, 0x67, 0x63, 0x03, 0x23, 0x13, 0x33, 0x0F, 0x73, 0x07, 0x27, 0x43,
            0x47, 0x4B, 0x4F, 0x53, 0x0B, 0x2B,
        ]);
        prop_oneof![
            1 => any::<u32>(),
            4 => (opcodes, any::<u32>()).prop_map(|(op, w)| (w & !0x7F) | op),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]
        #[test]
        fn random_programs_never_panic(
            words in proptest::collection::vec(word(), 1..48),
            regs in proptest::collection::vec(any::<u32>(), 64),
        ) {
            for &w in &words {
                if let Ok(ins) = decode(w) {
                    // Unused register fields are zeroed; x0 is never a source or destination.
                    prop_assert!(ins.info.src.iter().all(|r| *r != Reg::x(0) || r.is_none()));
                    prop_assert!(ins.rd < 32 && ins.rs1 < 32 && ins.rs2 < 32 && ins.rs3 < 32);
                }
            }
            let tri = dualsplit_geometry::Triangle::default();
            let mut image = MemoryImage::with_triangles(64, 0, vec![tri; 2].into());
            for (k, w) in image.words.iter_mut().enumerate() {
                *w = regs[k % 64];
            }
            let prog = Program::from_words(BASE, &words);
            let mut mem = FrameMemory::new(&image, &[0; 16], 64);
            let mut h = Hart::new(&prog, 256);
            // Registers point into the regions half the time.
            for k in 1..32 {
                let r = regs[k];
                h.x[k] = match r % 6 {
                    0 => r % 256,
                    1 => PARAMS_ADDR + r % 16,
                    2 => FRAME_BUFFER_ADDR + r % 64,
                    3 => LOCAL_STORE_ADDR + r % 256,
                    4 => BASE + 4 * (r % words.len() as u32),
                    _ => r,
                };
                h.f[k] = regs[32 + k];
            }
            for _ in 0..200 {
                match h.step(&prog, &mut mem) {
                    Ok(_) if h.halted => break,
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
        }
    }
}
