//! The simulator's layout (`docs/simulator.md`, "Code layout"): the hardware units under
//! `src/hw/` import nothing from the thread models (`src/model/`) or from what is built on
//! them, and no two files of `src/` import each other in a circle.
//!
//! Imports are read from the source: every `crate::a::b…` path outside comments and outside
//! the trailing `#[cfg(test)]` module, resolved to the longest module path that is a file.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Module path (`hw::tm`, `` for lib.rs) → source without comments and test modules.
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(root).unwrap().with_extension("");
                let parts: Vec<String> = rel
                    .iter()
                    .map(|s| s.to_string_lossy().into_owned())
                    .filter(|s| s != "mod")
                    .collect();
                let name = if parts == ["lib"] {
                    String::new()
                } else {
                    parts.join("::")
                };
                let src = std::fs::read_to_string(&p).unwrap();
                let src = match src.find("#[cfg(test)]\nmod tests") {
                    Some(i) => src[..i].to_string(),
                    None => src,
                };
                let code: String = src
                    .lines()
                    .filter(|l| !l.trim_start().starts_with("//"))
                    .collect::<Vec<_>>()
                    .join("\n");
                out.insert(name, code);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

/// Each module's imports of other modules of the crate.
fn imports(mods: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    // Re-exports (`pub use cycle::{Cycle, Tick};` in `hw/mod.rs`): `crate::hw::Cycle` is an
    // import of `hw::cycle`, not of `hw`. Per module: name → path from the crate root.
    let mut aliases: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for (module, src) in mods {
        for line in src.lines() {
            let Some(rest) = line.trim().strip_prefix("pub use ") else {
                continue;
            };
            let rest = rest.trim_end_matches(';');
            let (base, items) = match rest.split_once("::{") {
                Some((b, items)) => (b, items.trim_end_matches('}').split(',').collect()),
                None => match rest.rsplit_once("::") {
                    Some((b, item)) => (b, vec![item]),
                    None => continue,
                },
            };
            let base = match base.strip_prefix("crate::") {
                Some(b) => b.to_string(),
                None if module.is_empty() => base.to_string(),
                None => format!("{module}::{base}"),
            };
            for item in items {
                let item = item.trim();
                let (path, name) = match item.rsplit_once("::") {
                    Some((p, n)) => (format!("{base}::{p}"), n),
                    None => (base.clone(), item),
                };
                let name = name.rsplit(" as ").next().unwrap_or(name).trim();
                aliases
                    .entry(module.clone())
                    .or_default()
                    .insert(name.to_string(), path);
            }
        }
    }
    let resolve = |path: &str| -> String {
        let mut path = path.to_string();
        loop {
            let parts: Vec<&str> = path.split("::").collect();
            let k = (0..=parts.len())
                .rev()
                .find(|&k| mods.contains_key(&parts[..k].join("::")))
                .unwrap_or(0);
            let module = parts[..k].join("::");
            let next = parts.get(k).and_then(|n| aliases.get(&module)?.get(*n));
            match next {
                Some(target) if *target != module => {
                    path = std::iter::once(target.as_str())
                        .chain(parts[k + 1..].iter().copied())
                        .collect::<Vec<_>>()
                        .join("::");
                }
                _ => return module,
            }
        }
    };
    let mut out = BTreeMap::new();
    for (name, src) in mods {
        let mut deps = BTreeSet::new();
        for (i, _) in src.match_indices("crate::") {
            let rest = &src[i + 7..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let base = rest[..end].trim_end_matches(':');
            let mut targets = vec![base.to_string()];
            // `crate::a::{b, c::d}`: each item of the group.
            if rest[end..].starts_with('{') {
                let group = &rest[end + 1..rest[end..].find('}').map_or(end, |j| end + j)];
                targets = group
                    .split(',')
                    .map(|t| t.trim().split([' ', ':']).next().unwrap_or(""))
                    .filter(|t| !t.is_empty() && *t != "self")
                    .map(|t| format!("{base}::{t}"))
                    .collect();
                targets.push(base.to_string());
            }
            for t in targets {
                let m = resolve(&t);
                let inside = m.is_empty() || name == &m || name.starts_with(&format!("{m}::"));
                if !inside {
                    deps.insert(m);
                }
            }
        }
        out.insert(name.clone(), deps);
    }
    out
}

#[test]
fn hardware_units_import_no_thread_model() {
    let mods = modules();
    assert!(mods.contains_key("hw::tm") && mods.contains_key("model::rv32::tp"));
    let built_on_models = ["model", "engine", "frame", "result", "error", "accel"];
    for (m, deps) in imports(&mods) {
        if m.starts_with("hw") {
            for d in deps {
                assert!(
                    !built_on_models
                        .iter()
                        .any(|b| d == *b || d.starts_with(&format!("{b}::"))),
                    "{m} imports {d}"
                );
            }
        }
    }
}

#[test]
fn no_two_files_import_each_other_in_a_circle() {
    let mods = modules();
    let deps = imports(&mods);
    // Depth-first search for a back edge.
    fn visit(
        m: &str,
        deps: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) {
        state.insert(m.to_string(), 1);
        path.push(m.to_string());
        for d in deps.get(m).into_iter().flatten() {
            match state.get(d.as_str()) {
                Some(1) => panic!("import circle: {} -> {d}", path.join(" -> ")),
                Some(_) => {}
                None => visit(d, deps, state, path),
            }
        }
        path.pop();
        state.insert(m.to_string(), 2);
    }
    let mut state = BTreeMap::new();
    for m in deps.keys().filter(|m| !m.is_empty()) {
        if !state.contains_key(m.as_str()) {
            visit(m, &deps, &mut state, &mut Vec::new());
        }
    }
}
