//! ELF loading: the tiny fixture `fixtures/rv32_tiny.elf` (source and build command in
//! `fixtures/rv32_tiny.S`; the test needs no compiler) loads, runs to `ebreak` and writes
//! the expected frame-buffer words; malformed headers give typed errors.

use dualsplit_accel::MemoryImage;
use dualsplit_sim::model::rv32::{
    ElfError, FRAME_BUFFER_ADDR, FrameMemory, Hart, Op, PROGRAM_BASE, Program, RunError,
    run_to_halt,
};

const TINY: &[u8] = include_bytes!("fixtures/rv32_tiny.elf");

#[test]
fn tiny_elf_loads_and_runs() {
    let prog = Program::from_elf(TINY).unwrap();
    assert_eq!(prog.entry, PROGRAM_BASE);
    assert_eq!(prog.text_base(), PROGRAM_BASE);
    // .text is 14 instructions; .rodata (two floats) is data, not decoded.
    assert_eq!(prog.code().len(), 14);
    assert_eq!(prog.code()[13].op, Op::Ebreak);
    assert_eq!(prog.first_illegal(), None);
    assert_eq!(
        prog.read(PROGRAM_BASE + 0x38, 4),
        Some(&1.5f32.to_le_bytes()[..])
    );

    let image = MemoryImage::default();
    let mut mem = FrameMemory::new(&image, &[], 8);
    let mut hart = Hart::new(&prog, 64);
    let stats = run_to_halt(&mut hart, &prog, &mut mem, 1000).unwrap();
    assert_eq!(mem.frame_f32()[0], 3.75);
    assert_eq!(u32::from_le_bytes(mem.frame[4..8].try_into().unwrap()), 55);
    assert_eq!(stats.instructions, 9 + 3 * 10 + 2);
    assert_eq!(stats.taken_branches, 9);
    assert_eq!(hart.pc, PROGRAM_BASE + 13 * 4);
    assert!(hart.halted);

    // A budget too small is an error naming the pc.
    let mut hart = Hart::new(&prog, 64);
    let mut mem = FrameMemory::new(&image, &[], 8);
    assert!(matches!(
        run_to_halt(&mut hart, &prog, &mut mem, 10),
        Err(RunError::StepBudget { steps: 10, .. })
    ));
    // A frame buffer too small: the fsw faults with its pc and address.
    let mut hart = Hart::new(&prog, 64);
    let mut mem = FrameMemory::new(&image, &[], 0);
    let err = run_to_halt(&mut hart, &prog, &mut mem, 1000).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "pc {:#010x}: access to unmapped address {:#010x}",
            PROGRAM_BASE + 0x18,
            FRAME_BUFFER_ADDR
        )
    );
}

#[test]
fn malformed_elf_headers_are_typed_errors() {
    let patched = |at: usize, bytes: &[u8]| {
        let mut v = TINY.to_vec();
        v[at..at + bytes.len()].copy_from_slice(bytes);
        Program::from_elf(&v).unwrap_err()
    };
    assert_eq!(patched(4, &[2]), ElfError::Class(2));
    assert_eq!(patched(5, &[2]), ElfError::Endian(2));
    assert_eq!(patched(18, &62u16.to_le_bytes()), ElfError::Machine(62));
    assert_eq!(patched(16, &3u16.to_le_bytes()), ElfError::Type(3));
    assert!(matches!(
        patched(36, &3u32.to_le_bytes()),
        ElfError::Flags { flags: 3, .. }
    ));
    assert!(matches!(
        patched(36, &0u32.to_le_bytes()),
        ElfError::Flags { flags: 0, .. }
    ));
    // Entry outside the text, or misaligned.
    assert_eq!(
        patched(24, &0x9000_0000u32.to_le_bytes()),
        ElfError::Entry(0x9000_0000)
    );
    assert_eq!(
        patched(24, &(PROGRAM_BASE + 2).to_le_bytes()),
        ElfError::Entry(PROGRAM_BASE as u64 + 2)
    );
    assert!(matches!(
        Program::from_elf(&TINY[..40]),
        Err(ElfError::Parse(_))
    ));
    assert!(matches!(
        Program::from_elf(b"not an elf"),
        Err(ElfError::Parse(_))
    ));
}

#[test]
fn segments_outside_the_program_region_are_rejected() {
    // Move the one PT_LOAD segment's p_vaddr (program header at e_phoff, p_vaddr at +8).
    let phoff = u32::from_le_bytes(TINY[28..32].try_into().unwrap()) as usize;
    let phentsize = u16::from_le_bytes(TINY[42..44].try_into().unwrap()) as usize;
    let phnum = u16::from_le_bytes(TINY[44..46].try_into().unwrap()) as usize;
    let mut v = TINY.to_vec();
    let load = (0..phnum)
        .map(|k| phoff + k * phentsize)
        .find(|&p| u32::from_le_bytes(v[p..p + 4].try_into().unwrap()) == 1)
        .unwrap();
    v[load + 8..load + 12].copy_from_slice(&0x1000u32.to_le_bytes());
    assert!(matches!(
        Program::from_elf(&v),
        Err(ElfError::SegmentOutside { vaddr: 0x1000, .. })
    ));
    v[load + 8..load + 12].copy_from_slice(&0xEFFF_FFF0u32.to_le_bytes());
    assert!(matches!(
        Program::from_elf(&v),
        Err(ElfError::SegmentOutside {
            vaddr: 0xEFFF_FFF0,
            ..
        })
    ));
}
