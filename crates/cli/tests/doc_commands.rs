//! Every `dualsplit` command line the docs show is one the command line accepts.
//!
//! The docs are README.md, docs/*.md and kernels/README.md. Two rules:
//!
//! * **Concrete commands** in fenced code blocks (`dualsplit ARGS`, `$ dualsplit ARGS`, or
//!   `cargo run ... -- ARGS` of this binary; `\` continues a line, `#` starts a comment)
//!   are parsed by the real binary with the hidden `--parse-only` flag, which stops after
//!   clap has parsed them: an unknown subcommand or flag, a missing value or a value its
//!   parser refuses fails. The command runs in an empty folder where every relative path
//!   it names exists as an empty file (scenes are checked for existence while parsing);
//!   `$VAR` stands for `VAR`.
//! * **Synopses and fragments**: a fenced line with placeholders (`[...]`, `a|b`, `...`,
//!   an upper-case word such as `SCENE`), and every inline code span that starts with
//!   `dualsplit SUBCOMMAND`: the subcommand must exist and every flag the line names must
//!   be one of that subcommand's flags (as its `--help` lists them).
mod common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One command line found in a doc.
#[derive(Debug)]
struct DocCommand {
    /// `FILE:LINE`, for messages.
    at: String,
    /// The arguments after `dualsplit` (or after cargo's `--`).
    argv: Vec<String>,
    /// Whether only the subcommand and flag names are checked.
    synopsis: bool,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// README.md, kernels/README.md and docs/*.md, in a stable order.
fn doc_files() -> Vec<PathBuf> {
    let root = repo();
    let mut files = vec![root.join("README.md"), root.join("kernels/README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("read docs/")
        .map(|e| e.expect("docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// Splits a shell line into words: whitespace separates, single and double quotes group,
/// an unquoted `#` at the start of a word ends the line, and an unquoted `|`, `;`, `&&` or
/// `>` word ends the command. A quote that is never closed (an apostrophe in a synopsis's
/// prose, `report's`) is an ordinary character.
fn shell_words(line: &str) -> Vec<String> {
    split_words(line, true).unwrap_or_else(|| split_words(line, false).unwrap_or_default())
}

/// [`shell_words`] with or without quoting; `None` when a quote is left open.
fn split_words(line: &str, quoting: bool) -> Option<Vec<String>> {
    let mut words = Vec::new();
    let mut cur = String::new();
    let mut in_word = false;
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => cur.push(c),
            None if quoting && (c == '\'' || c == '"') => {
                quote = Some(c);
                in_word = true;
            }
            None if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut cur));
                    in_word = false;
                }
            }
            None if c == '#' && !in_word => break,
            None => {
                cur.push(c);
                in_word = true;
            }
        }
    }
    if quote.is_some() {
        return None;
    }
    if in_word {
        words.push(cur);
    }
    let end = words
        .iter()
        .position(|w| ["|", ";", "&&", "||", ">", "2>", "&"].contains(&w.as_str()))
        .unwrap_or(words.len());
    words.truncate(end);
    Some(words)
}

/// The `dualsplit` arguments of a shell line, or `None` when the line runs something else
/// (another program, a cargo example, another package's binary).
fn dualsplit_argv(words: &[String]) -> Option<Vec<String>> {
    let mut w = words;
    if w.first().is_some_and(|s| s == "$") {
        w = &w[1..];
    }
    // Environment assignments before the program.
    while w
        .first()
        .is_some_and(|s| s.contains('=') && !s.starts_with('-'))
    {
        w = &w[1..];
    }
    match w.first()?.as_str() {
        "dualsplit" => Some(w[1..].to_vec()),
        "cargo" if w.get(1).is_some_and(|s| s == "run") => {
            let split = w.iter().position(|s| s == "--")?;
            let cargo = &w[2..split];
            let other = cargo.iter().enumerate().any(|(i, s)| {
                s == "--example"
                    || s.starts_with("--example=")
                    || (["-p", "--package", "--bin"].contains(&s.as_str())
                        && cargo.get(i + 1).is_some_and(|n| n != "dualsplit"))
            });
            (!other).then(|| w[split + 1..].to_vec())
        }
        _ => None,
    }
}

/// Whether a line is a synopsis: optional parts, alternatives, repetition or placeholders.
fn is_synopsis(argv: &[String]) -> bool {
    argv.iter().any(|a| {
        a.contains('[')
            || a.contains('|')
            || a.contains("...")
            || a.contains('…')
            || a.contains('<')
            || (a.len() > 1 && a.chars().all(|c| c.is_ascii_uppercase() || c == '_'))
    })
}

/// Every command line of one doc.
fn commands_in(path: &Path) -> Vec<DocCommand> {
    let text = std::fs::read_to_string(path).expect("read doc");
    let name = path
        .strip_prefix(repo())
        .unwrap_or(path)
        .display()
        .to_string();
    let mut out = Vec::new();
    let mut in_fence = false;
    let mut pending: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let lineno = i + 1;
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            pending = None;
            continue;
        }
        if in_fence {
            let (start, mut joined) = pending.take().unwrap_or((lineno, String::new()));
            joined.push_str(line);
            if let Some(stripped) = joined.strip_suffix('\\') {
                pending = Some((start, format!("{stripped} ")));
                continue;
            }
            if let Some(argv) = dualsplit_argv(&shell_words(&joined)) {
                let synopsis = is_synopsis(&argv);
                out.push(DocCommand {
                    at: format!("{name}:{start}"),
                    argv,
                    synopsis,
                });
            }
        } else {
            // Inline code spans: the odd pieces between backticks.
            for span in line.split('`').skip(1).step_by(2) {
                let words = shell_words(span);
                if words.len() >= 2 && words[0] == "dualsplit" {
                    out.push(DocCommand {
                        at: format!("{name}:{lineno}"),
                        argv: words[1..].to_vec(),
                        synopsis: true,
                    });
                }
            }
        }
    }
    out
}

/// The subcommand of an argument list: its first word that is not a flag.
fn subcommand(argv: &[String]) -> Option<&str> {
    argv.iter()
        .map(String::as_str)
        .find(|a| !a.starts_with('-'))
}

/// The `--help` text of `dualsplit PATH…`, or the error it gave.
fn help_of(path: &[&str]) -> Result<String, String> {
    let dir = tempfile::tempdir().unwrap();
    let mut args = path.to_vec();
    args.push("--help");
    let out = common::dualsplit(&args, dir.path());
    if !out.status.success() {
        return Err(common::stderr(&out));
    }
    Ok(common::stdout(&out))
}

/// The subcommand path of an argument list: its first word that is not a flag, then each
/// following word that its parent's `--help` lists under "Commands:" (`scene convert`).
fn command_path(argv: &[String]) -> Option<Vec<&str>> {
    let first = subcommand(argv)?;
    let mut path = vec![first];
    let mut rest = argv.iter().skip_while(|a| a.as_str() != first).skip(1);
    while let Some(next) = rest.next().filter(|a| !a.starts_with('-')) {
        let Ok(help) = help_of(&path) else { break };
        let nested = help
            .lines()
            .skip_while(|l| !l.starts_with("Commands:"))
            .skip(1)
            .take_while(|l| l.starts_with("  "))
            .any(|l| l.split_whitespace().next() == Some(next.as_str()));
        if !nested {
            break;
        }
        path.push(next.as_str());
    }
    Some(path)
}

/// The flags `dualsplit PATH… --help` lists (long and short), or the error it gave.
fn flags_of(path: &[&str]) -> Result<BTreeSet<String>, String> {
    let help = help_of(path)?;
    let mut flags = BTreeSet::new();
    for line in help.lines() {
        let line = line.trim_start();
        if !line.starts_with('-') {
            continue;
        }
        for w in line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')) {
            if w.starts_with('-') && w.len() > 1 {
                flags.insert(w.to_string());
            }
        }
    }
    Ok(flags)
}

/// The flag names a synopsis word names: `[--json[=FILE]]` → `--json`,
/// `--eye/--target` → both, values and negative numbers → none.
fn flag_names(word: &str) -> Vec<String> {
    word.split('/')
        .map(|p| p.trim_start_matches('['))
        .filter(|p| {
            p.starts_with('-')
                && p.chars()
                    .nth(1)
                    .is_some_and(|c| c == '-' || c.is_alphabetic())
        })
        .map(|p| {
            p.split(['=', '[', ']', ',', '|', '.'])
                .next()
                .unwrap_or(p)
                .to_string()
        })
        .collect()
}

/// The values `--help` says `flag` accepts (`[possible values: a, b]`), or `None` when it
/// lists none (a free-form value).
fn possible_values(help: &str, flag: &str) -> Option<BTreeSet<String>> {
    // The flag's entry: from its line to the next flag's.
    let mut entry = String::new();
    let mut inside = false;
    for line in help.lines() {
        let t = line.trim_start();
        if t.starts_with('-') {
            inside = t
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
                .any(|w| w == flag);
        }
        if inside {
            entry.push(' ');
            entry.push_str(t);
        }
    }
    let start = entry.find("[possible values: ")? + "[possible values: ".len();
    let end = start + entry[start..].find(']')?;
    Some(
        entry[start..end]
            .split(',')
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .collect(),
    )
}

/// The alternatives a synopsis gives a flag's value (`--accel dst|bvh2`, `--accel=a|b`):
/// (flag, values) for each flag whose value is a list of `|`-separated plain names (no
/// placeholder, list or repetition).
fn value_alternatives(argv: &[String]) -> Vec<(String, BTreeSet<String>)> {
    let mut out = Vec::new();
    for (i, w) in argv.iter().enumerate() {
        let w = w.trim_start_matches('[');
        let (flag, value) = match w.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f, v.to_string()),
            _ if w.starts_with("--") && !w.contains(['[', ']']) => match argv.get(i + 1) {
                Some(v) => (w, v.clone()),
                None => continue,
            },
            _ => continue,
        };
        let value = value.trim_end_matches(']');
        let plain = |v: &str| {
            !v.is_empty()
                && v.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || "-+".contains(c))
        };
        if value.contains('|') && value.split('|').all(plain) {
            out.push((
                flag.to_string(),
                value.split('|').map(String::from).collect(),
            ));
        }
    }
    out
}

/// Problems with a synopsis: an unknown subcommand, flags it does not have, or a flag's
/// alternatives (`--accel a|b|c`) that are not exactly the values its `--help` lists.
fn check_synopsis(c: &DocCommand) -> Option<String> {
    let Some(path) = command_path(&c.argv) else {
        return Some("no subcommand".into());
    };
    let sub = path.join(" ");
    let flags = match flags_of(&path) {
        Ok(f) => f,
        Err(e) => return Some(format!("subcommand `{sub}`: {}", e.trim())),
    };
    let unknown: Vec<String> = c
        .argv
        .iter()
        .flat_map(|w| flag_names(w))
        .filter(|f| f != "--" && !flags.contains(f))
        .collect();
    if !unknown.is_empty() {
        return Some(format!("`{sub}` has no {}", unknown.join(", ")));
    }
    let help = help_of(&path).ok()?;
    for (flag, listed) in value_alternatives(&c.argv) {
        if let Some(accepted) = possible_values(&help, &flag)
            && listed != accepted
        {
            return Some(format!(
                "`{sub} {flag}` lists {} but accepts {}",
                listed.iter().cloned().collect::<Vec<_>>().join("|"),
                accepted.iter().cloned().collect::<Vec<_>>().join("|")
            ));
        }
    }
    None
}

/// Whether a word (or the value after `--flag=`) names a relative file path.
fn relative_path(word: &str) -> Option<&str> {
    let v = match word.split_once('=') {
        Some((flag, v)) if flag.starts_with("--") => v,
        _ if word.starts_with('-') => return None,
        _ => word,
    };
    let looks_like_path = (v.contains('/') || v.contains('.'))
        && v.chars().any(|c| c.is_ascii_alphabetic())
        && !v.contains(':')
        && !v.contains('=')
        && !v.starts_with('/');
    looks_like_path.then_some(v)
}

/// Problems with a concrete command: what clap refused.
fn check_concrete(c: &DocCommand) -> Option<String> {
    let dir = tempfile::tempdir().unwrap();
    // Two levels deep, so `../x` stays inside the temporary folder.
    let cwd = dir.path().join("a/b");
    std::fs::create_dir_all(&cwd).unwrap();
    let argv: Vec<String> = c.argv.iter().map(|w| w.replace('$', "")).collect();
    for w in &argv {
        if let Some(p) = relative_path(w) {
            let file = cwd.join(p);
            if let Some(parent) = file.parent() {
                std::fs::create_dir_all(parent).unwrap();
            }
            if !file.exists() {
                std::fs::write(&file, b"").unwrap();
            }
        }
    }
    let out = Command::new(env!("CARGO_BIN_EXE_dualsplit"))
        .arg("--parse-only")
        .args(&argv)
        .current_dir(&cwd)
        .env_remove("DUALSPLIT_SCENES")
        .output()
        .expect("run dualsplit");
    (!out.status.success()).then(|| common::stderr(&out).trim().to_string())
}

fn all_commands() -> Vec<DocCommand> {
    doc_files().iter().flat_map(|f| commands_in(f)).collect()
}

#[test]
fn every_command_line_in_the_docs_parses() {
    let commands = all_commands();
    let concrete = commands.iter().filter(|c| !c.synopsis).count();
    // The docs show commands in both forms; finding none means the extraction broke.
    assert!(concrete >= 5, "only {concrete} concrete commands found");
    assert!(commands.len() - concrete >= 10, "too few synopses found");
    let failures: Vec<String> = commands
        .iter()
        .filter_map(|c| {
            let problem = if c.synopsis {
                check_synopsis(c)
            } else {
                check_concrete(c)
            };
            problem.map(|p| format!("{}: dualsplit {}\n    {p}", c.at, c.argv.join(" ")))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} doc command lines do not parse:\n{}",
        failures.len(),
        commands.len(),
        failures.join("\n")
    );
}

/// The checks themselves fail on a flag or subcommand that does not exist.
#[test]
fn a_made_up_flag_or_subcommand_fails() {
    let doc = |argv: &[&str], synopsis| DocCommand {
        at: "test".into(),
        argv: argv.iter().map(|s| s.to_string()).collect(),
        synopsis,
    };
    assert!(check_concrete(&doc(&["report", "--dry-run"], false)).is_none());
    let e = check_concrete(&doc(&["report", "--no-such-flag"], false)).unwrap();
    assert!(e.contains("--no-such-flag"), "{e}");
    assert!(check_concrete(&doc(&["reprot"], false)).is_some());
    // A scene path is created; a value its parser refuses still fails.
    assert!(check_concrete(&doc(&["simulate", "../s/x.ply.gz", "--res", "64"], false)).is_none());
    assert!(check_concrete(&doc(&["simulate", "x.ply", "--accel", "bvh3"], false)).is_some());
    assert!(check_synopsis(&doc(&["bench", "SCENE", "[--peer", "embree]"], true)).is_none());
    let e = check_synopsis(&doc(&["bench", "SCENE", "[--peers", "embree]"], true)).unwrap();
    assert!(e.contains("--peers"), "{e}");
    assert!(check_synopsis(&doc(&["simulate", "[--eye/--targte]"], true)).is_some());
    assert!(check_synopsis(&doc(&["nosuch", "SCENE"], true)).is_some());
}

/// A synopsis that lists a flag's values must list exactly the ones it accepts (the
/// registry's names for `--accel`).
#[test]
fn a_synopsis_lists_exactly_the_values_a_flag_accepts() {
    let doc = |argv: Vec<String>| DocCommand {
        at: "test".into(),
        argv,
        synopsis: true,
    };
    let names: Vec<&str> = dualsplit_accel::TreeKind::ALL.map(|k| k.name()).to_vec();
    let all = names.join("|");
    let line = |v: &str| {
        doc(vec![
            "build".into(),
            "SCENE".into(),
            "--accel".into(),
            v.into(),
        ])
    };
    assert_eq!(check_synopsis(&line(&all)), None);
    let e = check_synopsis(&line(&names[1..].join("|"))).expect("a value left out fails");
    assert!(e.contains("accepts"), "{e}");
    let e = check_synopsis(&line(&format!("{all}|nosuch"))).expect("a made-up value fails");
    assert!(e.contains("nosuch"), "{e}");
}

#[test]
fn lines_are_split_as_a_shell_would() {
    let w = shell_words("$ dualsplit info 'builtin:x?t=5' --max-triangles 1000 # note");
    assert_eq!(
        w,
        [
            "$",
            "dualsplit",
            "info",
            "builtin:x?t=5",
            "--max-triangles",
            "1000"
        ]
    );
    let w = shell_words("plan [report's options] [--accel a,b]");
    assert_eq!(w, ["plan", "[report's", "options]", "[--accel", "a,b]"]);
    let argv = dualsplit_argv(&shell_words("cargo run --release -- report --full")).unwrap();
    assert_eq!(argv, ["report", "--full"]);
    let other = "cargo run --release -p dualsplit-scene --example preview -- builtin:atrium";
    assert!(dualsplit_argv(&shell_words(other)).is_none());
    assert!(is_synopsis(&shell_words("bench SCENE [--peer embree]")));
    assert!(!is_synopsis(&shell_words("simulate x.ply --res 64")));
    assert_eq!(flag_names("[--json[=FILE]]"), ["--json"]);
    assert_eq!(
        flag_names("[--eye/--target/--fov"),
        ["--eye", "--target", "--fov"]
    );
    assert!(flag_names("-1,2,3").is_empty());
}
