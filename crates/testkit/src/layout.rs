//! The import graph of a crate's source, for the layout tests: which file imports which,
//! read from the text, and the import circles in it.
//!
//! Imports are read from the source, outside comments, string literals and test-only modules
//! (`#[cfg(test)] mod name { … }`): every path that starts with `crate::`, `super::` or
//! `self::`, with a child module the file declares (`mod x;`), or with a name a `use`
//! brought in (`use crate::model::rv32;` then `rv32::frame::run`), resolved to the longest
//! module path that is a file; a `pub use` re-export leads to the module it re-exports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// `src` with the text of its string literals blanked (a message's words are no paths, and
/// its "use" is no declaration); char literals such as `'"'` are kept as they are.
fn blank_strings(src: &str) -> String {
    let mut out = String::with_capacity(src.len());
    let mut chars = src.chars();
    while let Some(c) = chars.next() {
        out.push(c);
        match c {
            '\'' => {
                // A char literal ('x' or '\x'), or a lifetime (left as it is).
                let mut ahead = chars.clone();
                let lit = match ahead.next() {
                    Some('\\') => ahead.nth(1) == Some('\''),
                    Some(_) => ahead.next() == Some('\''),
                    None => false,
                };
                if lit {
                    for c in chars.by_ref() {
                        out.push(c);
                        if c == '\'' {
                            break;
                        }
                    }
                }
            }
            '"' => {
                let mut escaped = false;
                for c in chars.by_ref() {
                    if c == '"' && !escaped {
                        out.push('"');
                        break;
                    }
                    escaped = c == '\\' && !escaped;
                    out.push(if c == '\n' { '\n' } else { ' ' });
                }
            }
            _ => {}
        }
    }
    out
}

/// `src` without its test-only modules (`#[cfg(test)]` then a `mod name {` line, to the
/// brace that closes it); `src`'s strings are blanked first ([`blank_strings`]), so every
/// brace left is code.
fn strip_test_modules(src: &str) -> String {
    let mut out = String::with_capacity(src.len());
    let mut lines = src.split_inclusive('\n').peekable();
    while let Some(line) = lines.next() {
        let next = lines.peek().map_or("", |l| l.trim());
        if line.trim() == "#[cfg(test)]" && next.contains("mod ") && next.ends_with('{') {
            let mut depth = 0i32;
            for l in lines.by_ref() {
                depth += l.matches('{').count() as i32 - l.matches('}').count() as i32;
                if depth <= 0 {
                    break;
                }
            }
            continue;
        }
        out.push_str(line);
    }
    out
}

/// Module path (`hw::tm`, `` for lib.rs) → source without comments and test modules, for
/// the crate at `crate_dir` (its `src/`).
pub fn modules(crate_dir: &Path) -> BTreeMap<String, String> {
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
                let src = strip_test_modules(&blank_strings(&src));
                let code: String = src
                    .lines()
                    .filter(|l| !l.trim_start().starts_with("//"))
                    .collect::<Vec<_>>()
                    .join("\n");
                out.insert(name, code);
            }
        }
    }
    let root = crate_dir.join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

/// Each module's imports of other modules of the crate.
pub fn imports(mods: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
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
                if name == "*" {
                    // A glob re-export names nothing by itself.
                    continue;
                }
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
        for path in absolute_paths(name, src, mods) {
            let m = resolve(&path);
            let inside = m.is_empty() || name == &m || name.starts_with(&format!("{m}::"));
            if !inside {
                deps.insert(m);
            }
        }
        out.insert(name.clone(), deps);
    }
    out
}

/// The parent of module `m` (`` for a top-level module).
fn parent(m: &str) -> String {
    m.rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

/// `base::rest`, or `rest` when `base` is the crate root.
fn join(base: &str, rest: &str) -> String {
    if base.is_empty() {
        rest.to_string()
    } else if rest.is_empty() {
        base.to_string()
    } else {
        format!("{base}::{rest}")
    }
}

/// The use trees of `src`: (bound name, path as written) for every leaf of every `use`
/// declaration (`use a::{b, c::d as e};` gives (b, a::b) and (e, a::c::d)).
fn use_bindings(src: &str) -> Vec<(String, String)> {
    fn leaves(prefix: &str, tree: &str, out: &mut Vec<(String, String)>) {
        let tree = tree.trim();
        if let Some(i) = tree.find('{') {
            let base = tree[..i].trim().trim_end_matches("::");
            let inner = &tree[i + 1..tree.rfind('}').filter(|&j| j > i).unwrap_or(tree.len())];
            // Split the group at top-level commas.
            let (mut depth, mut start) = (0, 0);
            for (j, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        leaves(&join_use(prefix, base), &inner[start..j], out);
                        start = j + 1;
                    }
                    _ => {}
                }
            }
            leaves(&join_use(prefix, base), &inner[start..], out);
            return;
        }
        if tree.is_empty() || tree == "*" {
            return;
        }
        // A glob binds no name; it imports from its module.
        if let Some(module) = tree.strip_suffix("::*") {
            out.push(("*".to_string(), join_use(prefix, module.trim())));
            return;
        }
        let (path, alias) = match tree.split_once(" as ") {
            Some((p, a)) => (p.trim(), Some(a.trim())),
            None => (tree, None),
        };
        let full = join_use(prefix, path);
        let last = full.rsplit("::").next().unwrap_or(&full).to_string();
        let (full, name) = if last == "self" {
            let p = full.trim_end_matches("::self").to_string();
            let n = p.rsplit("::").next().unwrap_or(&p).to_string();
            (p, n)
        } else {
            (full.clone(), last)
        };
        out.push((alias.unwrap_or(&name).to_string(), full));
    }
    fn join_use(a: &str, b: &str) -> String {
        match (a.is_empty(), b.is_empty()) {
            (true, _) => b.to_string(),
            (_, true) => a.to_string(),
            _ => format!("{a}::{b}"),
        }
    }
    let mut out = Vec::new();
    let flat: String = src.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut rest = flat.as_str();
    while let Some(i) = rest.find("use ") {
        // A declaration starts a statement or an item (after `;`, a brace, an attribute or
        // `pub`), never a word: "use" inside a string or a comment is not one.
        let before = rest[..i].trim_end();
        let before_ok = rest[..i].is_empty()
            || rest[..i].ends_with(' ')
                && (before.is_empty()
                    || before.ends_with([';', '{', '}', ']', ')'])
                    || before.ends_with(" pub")
                    || before == "pub");
        let after = &rest[i + 4..];
        let end = after.find(';').unwrap_or(after.len());
        if before_ok {
            leaves("", &after[..end], &mut out);
        }
        rest = &after[end.min(after.len())..];
    }
    out
}

/// Every path of `src` (the code of module `name`) that names a module of the crate, made
/// absolute from the crate root: `crate::…`, `super::…`, `self::…`, a child module's
/// `x::…`, and a name bound by a `use` of one of these.
fn absolute_paths(name: &str, src: &str, mods: &BTreeMap<String, String>) -> Vec<String> {
    let children: BTreeSet<String> = mods
        .keys()
        .filter(|m| parent(m) == name && !m.is_empty() && *m != name)
        .map(|m| m.rsplit("::").next().unwrap_or(m).to_string())
        .collect();
    // A path's first segment made absolute, or `None` for another crate's path.
    let start = |first: &str, bound: &BTreeMap<String, String>| -> Option<String> {
        match first {
            "crate" => Some(String::new()),
            "super" => Some(parent(name)),
            "self" => Some(name.to_string()),
            c if children.contains(c) => Some(join(name, c)),
            b => bound.get(b).cloned(),
        }
    };
    let absolute = |path: &str, bound: &BTreeMap<String, String>| -> Option<String> {
        let mut segs = path.split("::");
        let mut abs = start(segs.next()?, bound)?;
        for s in segs {
            abs = match s {
                "super" => parent(&abs),
                "self" => abs,
                s => join(&abs, s),
            };
        }
        Some(abs)
    };
    let mut bound = BTreeMap::new();
    let mut out = Vec::new();
    for (n, p) in use_bindings(src) {
        if let Some(abs) = absolute(&p, &bound) {
            out.push(abs.clone());
            bound.insert(n, abs);
        }
    }
    // Paths in the code: `a::b…` not preceded by `::` or an identifier character.
    let bytes = src.as_bytes();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < bytes.len() {
        if ident(bytes[i]) && (i == 0 || !(ident(bytes[i - 1]) || bytes[i - 1] == b':')) {
            let mut j = i;
            while j < bytes.len()
                && (ident(bytes[j]) || (bytes[j] == b':' && bytes.get(j + 1) == Some(&b':')))
            {
                j += if bytes[j] == b':' { 2 } else { 1 };
            }
            let path = src[i..j].trim_end_matches(':');
            if path.contains("::")
                && let Some(abs) = absolute(path, &bound)
            {
                out.push(abs);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// A circle of imports in `deps`, as the path that closes it, or `None`.
pub fn find_circle(deps: &BTreeMap<String, BTreeSet<String>>) -> Option<String> {
    fn visit(
        m: &str,
        deps: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<String> {
        state.insert(m.to_string(), 1);
        path.push(m.to_string());
        for d in deps.get(m).into_iter().flatten() {
            match state.get(d.as_str()) {
                Some(1) => return Some(format!("{} -> {d}", path.join(" -> "))),
                Some(_) => {}
                None => {
                    if let Some(c) = visit(d, deps, state, path) {
                        return Some(c);
                    }
                }
            }
        }
        path.pop();
        state.insert(m.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for m in deps.keys().filter(|m| !m.is_empty()) {
        if !state.contains_key(m.as_str())
            && let Some(c) = visit(m, deps, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reading of imports finds each kind of path, and a circle through them is found.
    #[test]
    fn a_circle_through_relative_paths_is_found() {
        let src = |s: &str| s.to_string();
        let mods: BTreeMap<String, String> = [
            (String::new(), src("mod a;\nmod b;")),
            (src("a"), src("mod inner;\npub use inner::Thing;")),
            (
                src("a::inner"),
                src("use super::super::b::{self, Other};\nfn f() { b::g(); }"),
            ),
            (src("b"), src("use crate::c as see;\nfn g() { see::h(); }")),
            (src("c"), src("fn h() { super::a::Thing::new(); }")),
            (
                src("d"),
                src("fn k() { std::mem::swap(x, y); other_crate::x(); }"),
            ),
        ]
        .into();
        let deps = imports(&mods);
        let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
        assert_eq!(deps["a::inner"], set(&["b"]));
        assert_eq!(deps["b"], set(&["c"]));
        assert_eq!(
            deps["c"],
            set(&["a::inner"]),
            "the re-export leads to a::inner"
        );
        assert_eq!(deps["d"], set(&[]), "other crates' paths are not imports");
        let c = find_circle(&deps).expect("a::inner -> b -> c -> a::inner");
        assert!(
            c.contains("a::inner") && c.contains("b") && c.contains("c"),
            "{c}"
        );
        let mut broken = deps.clone();
        broken.get_mut("c").unwrap().clear();
        assert_eq!(find_circle(&broken), None);
    }

    #[test]
    fn string_literals_are_blanked() {
        let src = "let s = \"a \\\" b; use crate::x\"; let c = '\"'; use crate::y;";
        let kept = blank_strings(src);
        assert!(
            !kept.contains("crate::x") && kept.contains("use crate::y"),
            "{kept}"
        );
        assert_eq!(kept.len(), src.len());
    }

    #[test]
    fn test_modules_are_cut() {
        let src = "use crate::a;\n#[cfg(test)]\nmod x;\nuse crate::b;\n#[cfg(test)]\npub(super) mod tests {\n    use crate::c;\n    fn f() {}\n}\nuse crate::d;\n";
        let kept = strip_test_modules(src);
        assert!(
            kept.contains("crate::b") && kept.contains("crate::d"),
            "{kept}"
        );
        assert!(!kept.contains("crate::c"), "{kept}");
    }

    #[test]
    fn a_glob_binds_no_name() {
        let mods: BTreeMap<String, String> = [
            (String::new(), "pub use b::*;".to_string()),
            (
                "a".to_string(),
                "use crate::c::*;\nuse super::*;".to_string(),
            ),
            ("b".to_string(), String::new()),
            ("c".to_string(), String::new()),
        ]
        .into();
        assert_eq!(imports(&mods)["a"], ["c".to_string()].into());
    }
}
