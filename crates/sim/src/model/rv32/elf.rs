//! The kernel program: an ELF32 RISC-V executable loaded into memory and pre-decoded.
//!
//! Parsing uses the `object` crate's ELF reader only (`default-features = false`,
//! features `read_core`, `elf`, `std`: a few seconds to build, no compression or other
//! formats). Validation: 32-bit class, little-endian, `EM_RISCV`, `ET_EXEC`, no RVC flag
//! (compressed instructions are not supported), single-float ABI; every `PT_LOAD` segment
//! inside the program region `0x8000_0000..0xF000_0000` of `docs/isa.md`; the entry inside
//! an executable segment.
//!
//! The program's bytes are one flat buffer from the lowest segment address to the highest
//! segment end (gaps between segments read as zero; `.bss` is zero). The program region is
//! read-only for the threads: kernels keep no writable globals (`kernels/Makefile` checks
//! that `.data`/`.bss` are empty), so a store there is an error rather than a per-thread
//! copy. Every word of the executable sections (of the executable segments when the file
//! has no section headers) is decoded once; words that do not decode become
//! [`Op::Illegal`] and are an error only if executed.

use super::decode::{Instr, decode, illegal};
use super::isa::Op;
use object::Endianness;
use object::elf;
use object::read::elf::{FileHeader, ProgramHeader, SectionHeader};

/// First byte address of the program region.
pub const PROGRAM_BASE: u32 = 0x8000_0000;
/// End (exclusive) of the program region; the local store starts here.
pub const PROGRAM_END: u32 = 0xF000_0000;

/// Why an ELF file cannot be loaded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ElfError {
    /// The `object` crate could not parse the file.
    #[error("not a readable ELF file: {0}")]
    Parse(String),
    /// Not ELFCLASS32.
    #[error("ELF class {0} is not ELFCLASS32")]
    Class(u8),
    /// Not little-endian.
    #[error("ELF data encoding {0} is not little-endian")]
    Endian(u8),
    /// Not EM_RISCV.
    #[error("ELF machine {0} is not EM_RISCV (243)")]
    Machine(u16),
    /// Not an executable.
    #[error("ELF type {0} is not ET_EXEC")]
    Type(u16),
    /// Unsupported ABI flags (compressed instructions, or a float ABI other than single).
    #[error("ELF flags {flags:#x}: {reason}")]
    Flags {
        /// `e_flags`.
        flags: u32,
        /// What is wrong.
        reason: &'static str,
    },
    /// A loadable segment outside the program region.
    #[error(
        "segment at {vaddr:#010x}..{end:#010x} is outside the program region 0x80000000..0xf0000000"
    )]
    SegmentOutside {
        /// Segment start.
        vaddr: u64,
        /// Segment end (exclusive).
        end: u64,
    },
    /// A segment whose file size exceeds its memory size, or whose data is missing.
    #[error("segment at {vaddr:#010x}: {reason}")]
    Segment {
        /// Segment start.
        vaddr: u64,
        /// What is wrong.
        reason: &'static str,
    },
    /// No executable segment.
    #[error("no executable PT_LOAD segment")]
    NoText,
    /// The entry point is not inside an executable segment, or misaligned.
    #[error("entry point {0:#010x} is not a 4-aligned address inside an executable segment")]
    Entry(u64),
}

/// A loaded program: its bytes, its decoded instructions and its entry point.
#[derive(Clone, Debug)]
pub struct Program {
    /// Entry point (byte address).
    pub entry: u32,
    /// Byte address of `code[0]`.
    text_base: u32,
    /// One decoded instruction per word of `[text_base, text_base + 4 len)`.
    code: Vec<Instr>,
    /// Byte address of `bytes[0]`.
    data_base: u32,
    /// The program's memory, `[data_base, data_base + bytes.len())`.
    bytes: Vec<u8>,
}

impl Program {
    /// A program of raw instruction words at `base` (no data), entry at `base`: for tests
    /// and hand-assembled snippets. `base` must be 4-aligned and the words must fit the
    /// address space.
    pub fn from_words(base: u32, words: &[u32]) -> Program {
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        Program::from_parts(base, base, bytes, base..base + 4 * words.len() as u32)
    }

    fn from_parts(entry: u32, data_base: u32, bytes: Vec<u8>, text: std::ops::Range<u32>) -> Self {
        let code = (text.start..text.end)
            .step_by(4)
            .map(|a| {
                let o = (a - data_base) as usize;
                let w = u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
                decode(w).unwrap_or_else(|_| illegal(w))
            })
            .collect();
        Program {
            entry,
            text_base: text.start,
            code,
            data_base,
            bytes,
        }
    }

    /// Loads an ELF32 RISC-V executable (see the module doc for the checks).
    pub fn from_elf(data: &[u8]) -> Result<Program, ElfError> {
        if data.len() < 16 || &data[..4] != b"\x7fELF" {
            return Err(ElfError::Parse("no ELF magic".into()));
        }
        // e_ident[EI_CLASS], e_ident[EI_DATA]
        if data[4] != 1 {
            return Err(ElfError::Class(data[4]));
        }
        if data[5] != 1 {
            return Err(ElfError::Endian(data[5]));
        }
        let header = elf::FileHeader32::<Endianness>::parse(data)
            .map_err(|e| ElfError::Parse(e.to_string()))?;
        let e = Endianness::Little;
        // The raw values for the errors (ELF32 header: e_type at 16, e_machine at 18,
        // e_flags at 36; the parse above checked the length).
        let u16_at = |o: usize| u16::from_le_bytes([data[o], data[o + 1]]);
        if header.e_machine(e) != elf::EM_RISCV {
            return Err(ElfError::Machine(u16_at(18)));
        }
        if header.e_type(e) != elf::ET_EXEC {
            return Err(ElfError::Type(u16_at(16)));
        }
        let flags = u32::from_le_bytes([data[36], data[37], data[38], data[39]]);
        if flags & 1 != 0 {
            return Err(ElfError::Flags {
                flags,
                reason: "compressed instructions (RVC) are not supported",
            });
        }
        if flags & 6 != 2 {
            // EF_RISCV_FLOAT_ABI != EF_RISCV_FLOAT_ABI_SINGLE
            return Err(ElfError::Flags {
                flags,
                reason: "float ABI is not ilp32f (single)",
            });
        }
        let phdrs = header
            .program_headers(e, data)
            .map_err(|e| ElfError::Parse(e.to_string()))?;
        struct Seg<'a> {
            vaddr: u32,
            memsz: u32,
            data: &'a [u8],
            exec: bool,
        }
        let mut segs = Vec::new();
        for ph in phdrs {
            if ph.p_type(e) != elf::PT_LOAD || ph.p_memsz(e) == 0 {
                continue;
            }
            let vaddr = ph.p_vaddr(e) as u64;
            let memsz = ph.p_memsz(e) as u64;
            let end = vaddr + memsz;
            if vaddr < PROGRAM_BASE as u64 || end > PROGRAM_END as u64 {
                return Err(ElfError::SegmentOutside { vaddr, end });
            }
            if (ph.p_filesz(e) as u64) > memsz {
                return Err(ElfError::Segment {
                    vaddr,
                    reason: "file size exceeds memory size",
                });
            }
            let bytes = ph.data(e, data).map_err(|_| ElfError::Segment {
                vaddr,
                reason: "data outside the file",
            })?;
            segs.push(Seg {
                vaddr: vaddr as u32,
                memsz: memsz as u32,
                data: bytes,
                exec: ph.p_flags(e).contains(elf::PF_X),
            });
        }
        let lo = segs.iter().map(|s| s.vaddr).min().ok_or(ElfError::NoText)?;
        let hi = segs.iter().map(|s| s.vaddr + s.memsz).max().unwrap_or(lo);
        let mut bytes = vec![0u8; (hi - lo) as usize];
        for s in &segs {
            let o = (s.vaddr - lo) as usize;
            bytes[o..o + s.data.len()].copy_from_slice(s.data);
        }
        let text_lo = segs.iter().filter(|s| s.exec).map(|s| s.vaddr).min();
        let text_hi = segs
            .iter()
            .filter(|s| s.exec)
            .map(|s| s.vaddr + s.memsz)
            .max();
        let (Some(text_lo), Some(text_hi)) = (text_lo, text_hi) else {
            return Err(ElfError::NoText);
        };
        // Narrow the decoded range to the executable sections when the file has section
        // headers (the text segment also holds .rodata).
        let sections = header
            .section_headers(e, data)
            .map_err(|e| ElfError::Parse(e.to_string()))?;
        let exec_sections = || {
            sections
                .iter()
                .filter(|s| s.sh_flags(e).contains(elf::SHF_EXECINSTR) && s.sh_size(e) > 0)
        };
        let sec_lo = exec_sections().map(|s| s.sh_addr(e)).min();
        let sec_hi = exec_sections().map(|s| s.sh_addr(e) + s.sh_size(e)).max();
        let (text_lo, text_hi) = match (sec_lo, sec_hi) {
            (Some(lo), Some(hi)) => (lo.max(text_lo), hi.min(text_hi)),
            _ => (text_lo, text_hi),
        };
        let text_lo = text_lo & !3;
        let text_hi = (text_hi & !3).max(text_lo);
        let entry = header.e_entry(e) as u64;
        let in_exec = segs
            .iter()
            .any(|s| s.exec && entry >= s.vaddr as u64 && entry < (s.vaddr + s.memsz) as u64);
        if !in_exec || !entry.is_multiple_of(4) {
            return Err(ElfError::Entry(entry));
        }
        Ok(Program::from_parts(
            entry as u32,
            lo,
            bytes,
            text_lo..text_hi,
        ))
    }

    /// The decoded instruction at `pc`, or `None` when `pc` is misaligned or outside the
    /// text.
    #[inline(always)]
    pub fn fetch(&self, pc: u32) -> Option<&Instr> {
        let off = pc.wrapping_sub(self.text_base);
        if off & 3 != 0 {
            return None;
        }
        self.code.get((off >> 2) as usize)
    }

    /// Byte address of the first decoded instruction.
    pub fn text_base(&self) -> u32 {
        self.text_base
    }

    /// The decoded instructions, from [`Program::text_base`].
    pub fn code(&self) -> &[Instr] {
        &self.code
    }

    /// The program's bytes from byte address [`Program::data_base`].
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Byte address of the program's first byte.
    pub fn data_base(&self) -> u32 {
        self.data_base
    }

    /// The first word of the text that does not decode, with its address (the text of a
    /// compiled kernel should have none, apart from constant pools).
    pub fn first_illegal(&self) -> Option<(u32, u32)> {
        self.code
            .iter()
            .enumerate()
            .find(|(_, i)| i.op == Op::Illegal)
            .map(|(k, i)| (self.text_base + 4 * k as u32, i.imm as u32))
    }

    /// `n` bytes at `addr` of the program's memory, or `None` outside it.
    #[inline(always)]
    pub fn read(&self, addr: u32, n: usize) -> Option<&[u8]> {
        let o = addr.wrapping_sub(self.data_base) as usize;
        self.bytes.get(o..o.checked_add(n)?)
    }
}
