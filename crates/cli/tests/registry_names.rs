//! Generic code names no structure: a structure lives in its folder
//! (`crates/accel/src/<module>/`), its registry lines (`crates/accel/src/registry.rs`, the
//! `sim_accels!` invocation of `crates/sim/src/accel.rs`), its kernel (`kernels/`) and its
//! docs, and everything else reaches it through the registry (`docs/extending.md`).
//!
//! "Names a structure" is read off the registries, so a new structure is covered without
//! touching this test. For every structure but the reference (the BVH2 every other one is
//! derived from, which generic code may name as [`TreeKind::REFERENCE`]):
//!
//! * its module path (`dst::`), when the structure has a module of its own;
//! * its tree type (`DstTree`) and its [`TreeKind`] variant used as a type (`Dst`);
//! * a [`TreeKind`], [`AccelKind`] or [`SimAccel`] variant of it (`AccelKind::DstSw`);
//! * a string literal that is one of its command-line names (`"dst-q"`, `"cwbvh+"`).
//!
//! Non-test Rust code is read (comments, doc comments and `#[cfg(test)]` modules left out)
//! in every crate's `src/` and in `python/src/`, except the structures' folders, the
//! registry files and test support (`crates/testkit`). The names that generic code still
//! holds are listed in [`KNOWN`], each with its reason; an entry that no longer matches
//! fails too, so the list only shrinks.

use dualsplit_accel::{AccelKind, TreeKind};
use dualsplit_sim::SimAccel;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Names generic code still holds: (file, name, why). Each must still occur there.
#[rustfmt::skip]
const KNOWN: &[(&str, &str, &str)] = &[
    // The paper's reproduction: its tables and figures compare the paper's structures by
    // name (Table 3, Tables 4–7, the "Beyond the paper" study), as the paper does.
    ("crates/report/src/beyond.rs", "*", "the report's study of named structures"),
    ("crates/report/src/produce.rs", "*", "the report's paper tables"),
    ("crates/report/src/summary.rs", "*", "the report's paper summary"),
    ("crates/report/src/tables.rs", "*", "the report's paper tables"),
    ("crates/report/src/study/job.rs", "*", "the study's default configurations"),
    ("crates/report/src/study/variants.rs", "*", "the study's DST variants"),
    // `dualsplit stats` compares the DST's conversion presets (the paper's §4.2 study).
    ("crates/cli/src/cmd/stats.rs", "dst::", "the DST-preset study of `dualsplit stats`"),
    ("crates/cli/src/cmd/stats.rs", "Dst", "the DST-preset study of `dualsplit stats`"),
    // The traversal contract and the `fast` model's events have a dual-split node step
    // (its node kind and its `StepOutcome`), as they have a BVH node step.
    ("crates/accel/src/observer.rs", "Dst", "NodeStep::Dst, the DST's step event"),
    ("crates/sim/src/model/fast/event.rs", "Dst", "Event::Dst, the DST's step event"),
    // `dualsplit stats --json`'s schema has the DST's node-kind breakdown.
    ("crates/accel/src/stats.rs", "dst::", "StructureStats::dst (DstStats), a JSON field"),
    // The simulated units and instructions of the structures' hardware: the dual-split
    // pipelines' `rt.dstp`/`rt.dstqp` and the quantized box pipeline's `rt.qboxn` compute
    // what the structure's own step function computes (its kernel's other half).
    ("crates/sim/src/model/rv32/hart.rs", "dst::", "rt.dstp executes dst::pipeline::step"),
    ("crates/sim/src/model/rv32/hart.rs", "dstq::", "rt.dstqp executes dstq::unit_step"),
    ("crates/sim/src/model/rv32/hart.rs", "cwbvh::", "rt.qboxn decodes cwbvh boxes"),
];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One structure's names.
struct Names {
    kind: TreeKind,
    /// `dst::`, or `None` when it shares the reference's module.
    module: Option<String>,
    /// Identifiers that name it: its tree type and its variant names.
    idents: BTreeSet<String>,
    /// Enum paths that name it: `AccelKind::DstSw`, `SimAccel::DstQ`.
    paths: BTreeSet<String>,
    /// Its command-line names, quoted.
    literals: BTreeSet<String>,
}

/// The module and type of a registry entry's Rust type (`crate :: dst :: DstTree`).
fn module_and_type(kind: TreeKind) -> (String, String) {
    let parts: Vec<String> = kind
        .rust_type()
        .split("::")
        .map(|p| p.trim().to_string())
        .collect();
    (
        parts[parts.len() - 2].clone(),
        parts[parts.len() - 1].clone(),
    )
}

fn names() -> Vec<Names> {
    let (ref_module, ref_type) = module_and_type(TreeKind::REFERENCE);
    TreeKind::ALL
        .into_iter()
        .filter(|&k| k != TreeKind::REFERENCE)
        .map(|kind| {
            let (module, ty) = module_and_type(kind);
            let mut idents = BTreeSet::new();
            if ty != ref_type {
                idents.insert(ty);
            }
            let mut paths = BTreeSet::new();
            let mut literals = BTreeSet::new();
            paths.insert(format!("TreeKind::{kind:?}"));
            idents.insert(format!("{kind:?}"));
            literals.insert(format!("\"{}\"", kind.name()));
            for a in kind.accel_kinds() {
                paths.insert(format!("AccelKind::{a:?}"));
                literals.insert(format!("\"{}\"", a.name()));
            }
            for s in SimAccel::ALL
                .into_iter()
                .filter(|s| s.kind().tree_kind() == kind)
            {
                paths.insert(format!("SimAccel::{s:?}"));
                literals.insert(format!("\"{}\"", s.name()));
            }
            Names {
                kind,
                module: (module != ref_module).then(|| format!("{module}::")),
                idents,
                paths,
                literals,
            }
        })
        .collect()
}

/// The folders generic code is not read in: the structures' own, and test support.
fn skipped_dirs() -> Vec<PathBuf> {
    let root = repo();
    let mut dirs: Vec<PathBuf> = TreeKind::ALL
        .into_iter()
        .map(|k| root.join("crates/accel/src").join(module_and_type(k).0))
        .collect();
    dirs.push(root.join("crates/testkit"));
    dirs
}

const REGISTRY_FILES: [&str; 2] = ["crates/accel/src/registry.rs", "crates/sim/src/accel.rs"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.map(|e| e.expect("dir entry").path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The generic source files, relative to the repository root.
fn generic_files() -> Vec<(String, PathBuf)> {
    let root = repo();
    let mut files = Vec::new();
    for e in std::fs::read_dir(root.join("crates")).expect("crates/") {
        rust_files(&e.expect("crate").path().join("src"), &mut files);
    }
    rust_files(&root.join("python/src"), &mut files);
    let skipped = skipped_dirs();
    let root = root.canonicalize().expect("repo root");
    files
        .into_iter()
        .filter_map(|p| {
            let p = p.canonicalize().expect("source file");
            if skipped
                .iter()
                .any(|d| d.canonicalize().map(|d| p.starts_with(d)).unwrap_or(false))
            {
                return None;
            }
            let rel = p
                .strip_prefix(&root)
                .ok()?
                .to_string_lossy()
                .replace('\\', "/");
            let name = p.file_name()?.to_string_lossy().to_string();
            if REGISTRY_FILES.contains(&rel.as_str())
                || name == "tests.rs"
                || name.ends_with("_tests.rs")
            {
                return None;
            }
            Some((rel, p))
        })
        .collect()
}

/// The code of a source file: comments dropped, the `#[cfg(test)]` module and what follows
/// it dropped. Returns (line number, code) pairs.
fn code_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]") {
            break;
        }
        let code = strip_comment(line);
        if !code.trim().is_empty() {
            out.push((i + 1, code));
        }
    }
    out
}

/// `line` without a `//` comment outside a string literal.
fn strip_comment(line: &str) -> String {
    let b = line.as_bytes();
    let mut in_str = false;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'\\' if in_str => i += 1,
            b'"' => in_str = !in_str,
            b'/' if !in_str && b.get(i + 1) == Some(&b'/') => return line[..i].to_string(),
            _ => {}
        }
        i += 1;
    }
    line.to_string()
}

fn is_ident_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// Where `needle` occurs in `hay` as a whole token: not inside a longer identifier, and for
/// a bare identifier not as the last segment of a path (`NodeStep::Dst` is not the type
/// `Dst`).
fn occurs(hay: &str, needle: &str, bare_ident: bool) -> bool {
    let h = hay.as_bytes();
    let n = needle.as_bytes();
    let mut from = 0;
    while let Some(at) = hay[from..].find(needle) {
        let s = from + at;
        let e = s + needle.len();
        let before_ok = s == 0 || !is_ident_byte(h[s - 1]) || !is_ident_byte(n[0]);
        let after_ok = e >= h.len() || !is_ident_byte(h[e]) || !is_ident_byte(n[n.len() - 1]);
        let path_ok = !(bare_ident && s >= 2 && &hay[s - 2..s] == "::");
        if before_ok && after_ok && path_ok {
            return true;
        }
        from = s + 1;
    }
    false
}

/// Every (file, name, line) where generic code names a structure.
fn findings(files: &[(String, PathBuf)], names: &[Names]) -> Vec<(String, String, String)> {
    let mut found = Vec::new();
    for (rel, path) in files {
        let text = std::fs::read_to_string(path).expect("read source");
        for (line, code) in code_lines(&text) {
            for n in names {
                let hits = n
                    .module
                    .iter()
                    .filter(|m| occurs(&code, m, false))
                    .chain(n.paths.iter().filter(|p| occurs(&code, p, false)))
                    .chain(n.literals.iter().filter(|l| occurs(&code, l, false)))
                    .chain(n.idents.iter().filter(|i| occurs(&code, i, true)));
                for hit in hits {
                    found.push((
                        rel.clone(),
                        hit.clone(),
                        format!("{rel}:{line}: `{hit}` ({}): {}", n.kind, code.trim()),
                    ));
                }
            }
        }
    }
    found
}

fn known(rel: &str, name: &str) -> bool {
    KNOWN
        .iter()
        .any(|&(f, n, _)| f == rel && (n == "*" || n == name))
}

#[test]
fn generic_code_names_no_structure() {
    let names = names();
    assert!(
        !names.is_empty(),
        "the registry lists structures besides the reference"
    );
    let files = generic_files();
    assert!(
        files.iter().any(|(r, _)| r == "crates/accel/src/lib.rs"),
        "the accel crate's generic files are read"
    );
    let found = findings(&files, &names);
    let unknown: Vec<&String> = found
        .iter()
        .filter(|(rel, name, _)| !known(rel, name))
        .map(|(_, _, msg)| msg)
        .collect();
    assert!(
        unknown.is_empty(),
        "generic code names a structure (reach it through the registry instead):\n{}",
        unknown
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
    let stale: Vec<String> = KNOWN
        .iter()
        .filter(|&&(f, n, _)| {
            !found
                .iter()
                .any(|(rel, name, _)| rel == f && (n == "*" || n == name))
        })
        .map(|(f, n, why)| format!("{f}: `{n}` ({why})"))
        .collect();
    assert!(
        stale.is_empty(),
        "KNOWN lists names generic code no longer holds; drop them:\n{}",
        stale.join("\n")
    );
}

/// The scan finds what it must: each kind of name in a line of code, not in a comment, not
/// as another path's last segment.
#[test]
fn the_scan_finds_names_and_skips_comments() {
    let names = names();
    let (module, ty) = module_and_type(TreeKind::ALL[TreeKind::ALL.len() - 1]);
    let a = AccelKind::ALL[AccelKind::ALL.len() - 1];
    let sample = format!(
        "use crate::{module}::{ty};\nlet k = AccelKind::{a:?};\nlet s = \"{}\";\n\
         // AccelKind::{a:?} in a comment\nlet e = Event::{:?}(x);\n#[cfg(test)]\nlet t = \"{}\";\n",
        a.name(),
        a.tree_kind(),
        a.name()
    );
    let dir = std::env::temp_dir().join(format!("registry-names-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let f = dir.join("sample.rs");
    std::fs::write(&f, sample).expect("write sample");
    let found = findings(&[("sample.rs".into(), f)], &names);
    let lines: BTreeSet<&str> = found
        .iter()
        .map(|(_, _, m)| m.split(':').nth(1).unwrap_or(""))
        .collect();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        lines,
        BTreeSet::from(["1", "2", "3"]),
        "found: {:#?}",
        found.iter().map(|f| &f.2).collect::<Vec<_>>()
    );
}

/// The names of one `Name = Literal[...]` line of the Python stub, as a set.
fn stub_literal(stub: &str, name: &str) -> BTreeSet<String> {
    let start = stub
        .find(&format!("{name} = Literal["))
        .unwrap_or_else(|| panic!("the stub defines {name}"));
    let rest = &stub[start..];
    let body = &rest[rest.find('[').expect("[") + 1..rest.find(']').expect("]")];
    body.split(',')
        .map(|s| s.trim().trim_matches('"').to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

/// Python's type stub lists the registries' names: the structures, traversals and
/// simulated configurations (with `all`) the extension module exports as `STRUCTURES`,
/// `TRAVERSALS` and `CONFIGURATIONS`.
#[test]
fn the_python_stub_lists_the_registries_names() {
    let stub = std::fs::read_to_string(repo().join("python/dualsplit/__init__.pyi"))
        .expect("read the stub");
    let set = |names: Vec<&str>| names.into_iter().map(String::from).collect::<BTreeSet<_>>();
    assert_eq!(
        stub_literal(&stub, "StructureKind"),
        set(TreeKind::ALL.map(TreeKind::name).to_vec())
    );
    assert_eq!(
        stub_literal(&stub, "Traversal"),
        set(AccelKind::ALL.map(AccelKind::name).to_vec())
    );
    let mut configs = set(SimAccel::ALL.map(SimAccel::name).to_vec());
    configs.insert("all".into());
    assert_eq!(stub_literal(&stub, "SimConfigName"), configs);
}
