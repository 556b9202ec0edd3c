//! The ray-tracing instructions' encodings come from one table
//! (`dualsplit_sim::model::rv32::isa::RT_INSTRUCTIONS`): the decoder reads it, and this test
//! checks that `kernels/rt.h` (what the kernels emit) and `docs/isa.md` (the contract) say
//! the same, row by row, and that the decoder accepts exactly the table's function fields.

use dualsplit_sim::model::rv32::decode;
use dualsplit_sim::model::rv32::isa::{Format, RT_INSTRUCTIONS};
use std::collections::BTreeMap;

fn repo_file(path: &str) -> String {
    let p = format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
}

/// (opcode, funct3, format letter, largest function field) per mnemonic, from `rt.h`'s
/// `.insn` lines: `.insn r4 OPC, F3, F2, …`, `.insn r OPC, F3, F7, …` or `.insn i OPC, F3,
/// x%N, …` (the `P` index in the rd field), the function field a number or `%N` (an operand:
/// its range is given by the function's comment as `N = 2, 4, 8 -> funct2 = 0, 1, 2` or
/// `k a constant 0-7`, checked through the decoder).
fn from_rt_h() -> BTreeMap<String, (u32, u32, char, Option<u32>)> {
    let src = repo_file("kernels/rt.h");
    let mut out = BTreeMap::new();
    let mut name = None;
    for line in src.lines() {
        let l = line.trim();
        for prefix in [
            "static inline float ",
            "static inline uint32_t ",
            "static inline void ",
        ] {
            if let Some(rest) = l.strip_prefix(prefix) {
                name = rest.split('(').next().map(str::to_string);
            }
        }
        if let Some(rest) = l.strip_prefix("#define ") {
            let n = rest.split(['(', ' ']).next().unwrap_or("");
            if n.starts_with("rt_") {
                name = Some(n.to_string());
            }
        }
        let Some(i) = l.find(".insn ") else { continue };
        let insn = &l[i + 6..];
        let (fmt, rest) = insn.split_once(' ').unwrap();
        let fields: Vec<&str> = rest.split(',').map(str::trim).collect();
        let num = |s: &str| -> Option<u32> {
            if let Some(h) = s.strip_prefix("0x") {
                u32::from_str_radix(h, 16).ok()
            } else {
                s.parse().ok()
            }
        };
        let n = name
            .take()
            .expect(".insn without a function name before it");
        let mnemonic = match n.as_str() {
            "rt_dst_tmin" | "rt_dst_tmax" | "rt_dst_offset_stack" | "rt_dst_code" => {
                "rt.dstget".to_string()
            }
            "rt_boxexit" => "rt.boxget".to_string(),
            other => other.replacen("rt_", "rt.", 1),
        };
        let letter = match fmt {
            "r4" => '4',
            "i" => 'i',
            _ => 'r',
        };
        let f = num(fields[2]);
        let e = out.entry(mnemonic).or_insert((
            num(fields[0]).unwrap(),
            num(fields[1]).unwrap(),
            letter,
            f,
        ));
        // Several functions of one instruction (rt.dstget's fields): keep the largest.
        if let (Some(a), Some(b)) = (e.3, f) {
            e.3 = Some(a.max(b));
        }
    }
    out
}

/// (opcode, funct3, format letter) per mnemonic, from `docs/isa.md`'s encoding table.
fn from_isa_md() -> BTreeMap<String, (u32, u32, char)> {
    let md = repo_file("docs/isa.md");
    let mut out = BTreeMap::new();
    for line in md.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 6 || !cells[1].starts_with("`rt.") {
            continue;
        }
        let mnemonic = cells[1].trim_matches('`').to_string();
        let opcode = cells[2]
            .split('`')
            .nth(1)
            .and_then(|h| u32::from_str_radix(h.trim_start_matches("0x"), 16).ok())
            .unwrap_or_else(|| panic!("isa.md: opcode of {mnemonic}: {:?}", cells[2]));
        let funct3 = cells[3].parse().unwrap();
        let letter = if cells[4].starts_with("f2") {
            '4'
        } else if cells[4].starts_with("rd") {
            'i'
        } else {
            'r'
        };
        out.insert(mnemonic, (opcode, funct3, letter));
    }
    out
}

#[test]
fn rt_table_agrees_with_rt_h_and_isa_md() {
    let rt_h = from_rt_h();
    let md = from_isa_md();
    let names: Vec<&str> = RT_INSTRUCTIONS.iter().map(|e| e.mnemonic).collect();
    assert_eq!(
        rt_h.keys().map(String::as_str).collect::<Vec<_>>(),
        {
            let mut n = names.clone();
            n.sort();
            n
        },
        "rt.h's instructions are not the table's"
    );
    assert_eq!(
        md.len(),
        RT_INSTRUCTIONS.len(),
        "isa.md's rows are not the table's"
    );
    for e in &RT_INSTRUCTIONS {
        let (letter, max) = match e.format {
            Format::R4 { funct2_max } => ('4', funct2_max),
            Format::R { funct7_max } => ('r', funct7_max),
            Format::I { rd_max, .. } => ('i', rd_max),
        };
        let h = rt_h[e.mnemonic];
        assert_eq!(
            (h.0, h.1, h.2),
            (e.opcode, e.funct3, letter),
            "rt.h: {}",
            e.mnemonic
        );
        if let Some(f) = h.3 {
            assert!(
                f <= max,
                "rt.h: {} emits function field {f} > {max}",
                e.mnemonic
            );
        }
        assert_eq!(
            md[e.mnemonic],
            (e.opcode, e.funct3, letter),
            "isa.md: {}",
            e.mnemonic
        );
    }
}

#[test]
fn the_decoder_accepts_exactly_the_tables_function_fields() {
    for e in &RT_INSTRUCTIONS {
        let rd = if matches!(e.format, Format::I { .. }) {
            0
        } else {
            5 << 7
        };
        let base = e.opcode | e.funct3 << 12 | rd | 6 << 15 | 7 << 20;
        let (shift, width, max) = match e.format {
            Format::R4 { funct2_max } => (25, 4, funct2_max),
            Format::R { funct7_max } => (25, 128, funct7_max),
            Format::I { rd_max, .. } => (7, 32, rd_max),
        };
        for f in 0..width {
            let w = base | f << shift | if width == 4 { 8 << 27 } else { 0 };
            let d = decode(w);
            if f <= max {
                let i = d.unwrap_or_else(|err| panic!("{} field {f}: {err}", e.mnemonic));
                assert_eq!(i.op, e.op, "{} field {f}", e.mnemonic);
                if let Format::I { p_base, .. } = e.format {
                    // The P index, and the byte offset from bits 20-31.
                    let k = u32::from(i.rd) + 32 * u32::from(i.rs2);
                    assert_eq!(k, p_base + f, "{}", e.mnemonic);
                    assert_eq!((i.rs1, i.imm), (6, 7), "{}", e.mnemonic);
                }
            } else {
                assert!(d.is_err(), "{} field {f} decoded", e.mnemonic);
            }
        }
    }
}
