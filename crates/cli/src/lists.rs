//! Lists on the command line take commas (`--accel bvh2,dst`, `--tms 32,64`,
//! `--eye 1,2,3`). A second value separated by a space would be read as a scene or
//! rejected with a message about an unexpected argument, so the raw arguments are checked
//! before parsing and such a value is refused with a message that says how to write it.
use std::path::Path;

/// What the items of an option's value are.
#[derive(Clone, Copy)]
enum Item {
    /// A structure or configuration name, or `all`.
    Accel,
    /// A positive whole number.
    Count,
    /// A number (a vector component).
    Number,
}

/// The options whose values are lists, and their items.
const LIST_OPTIONS: [(&str, Item); 6] = [
    ("--accel", Item::Accel),
    ("--tms", Item::Count),
    ("--res", Item::Count),
    ("--eye", Item::Number),
    ("--target", Item::Number),
    ("--light", Item::Number),
];

fn is_item(kind: Item, s: &str) -> bool {
    match kind {
        Item::Accel => {
            s == "all"
                || dualsplit_accel::AccelKind::parse(s).is_some()
                || dualsplit_sim::SimAccel::parse(s).is_some()
        }
        Item::Count => s.parse::<u32>().is_ok(),
        Item::Number => s.parse::<f64>().is_ok(),
    }
}

/// Finds a list item written after a space (`--tms 32 64`) in `args` (without the program
/// name) and says how to write it. A token that names an existing file is taken as the
/// scene it is.
pub fn space_separated(args: &[String]) -> Option<String> {
    let mut i = 0;
    while i < args.len() {
        let tok = &args[i];
        let (opt, value, next) = match tok.split_once('=') {
            Some((o, v)) if o.starts_with("--") => (o, v.to_string(), i + 1),
            _ => match args.get(i + 1) {
                Some(v) if tok.starts_with("--") => (tok.as_str(), v.clone(), i + 2),
                _ => {
                    i += 1;
                    continue;
                }
            },
        };
        let Some(&(_, kind)) = LIST_OPTIONS.iter().find(|(o, _)| *o == opt) else {
            i += 1;
            continue;
        };
        if let Some(extra) = args.get(next) {
            let is_option = extra.starts_with('-') && extra.parse::<f64>().is_err();
            if !is_option && is_item(kind, extra) && !Path::new(extra).exists() {
                let sep = if matches!(kind, Item::Count) && opt == "--res" {
                    "x"
                } else {
                    ","
                };
                return Some(format!(
                    "`{extra}` follows `{opt} {value}`: the values of {opt} are separated by `{sep}`, not by spaces (write `{opt} {value}{sep}{extra}`)"
                ));
            }
        }
        i = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::space_separated;

    fn check(line: &str) -> Option<String> {
        let args: Vec<String> = line.split_whitespace().map(String::from).collect();
        space_separated(&args)
    }

    #[test]
    fn space_separated_values_are_refused() {
        let e = check("report --tms 32 64").unwrap();
        assert!(e.contains("--tms 32,64"), "{e}");
        let e = check("simulate builtin:cornell --accel bvh2 dst").unwrap();
        assert!(e.contains("--accel bvh2,dst"), "{e}");
        let e = check("render builtin:cornell --eye=1 2 3 -o x.png").unwrap();
        assert!(e.contains("--eye 1,2"), "{e}");
        let e = check("render builtin:cornell --eye 1,2 -3 -o x.png").unwrap();
        assert!(e.contains("--eye 1,2,-3"), "{e}");
        let e = check("simulate builtin:cornell --res 64 64").unwrap();
        assert!(e.contains("--res 64x64"), "{e}");
    }

    #[test]
    fn comma_lists_and_following_arguments_pass() {
        assert_eq!(check("report --tms 32,64 builtin:atrium"), None);
        assert_eq!(
            check("simulate builtin:cornell --accel bvh2,dst --res 64"),
            None
        );
        assert_eq!(check("bench --accel bvh2 builtin:cornell --json"), None);
        assert_eq!(
            check("render builtin:cornell --eye -1,2,3 --fov 40 -o x.png"),
            None
        );
    }
}
