//! Leaf merging: a subtree of at most [`MERGE_MAX`] triangles becomes one leaf of the copy.

use crate::image::{ChildKind, NodeLayout, RUN_END};

/// The most triangles of a subtree that the copy turns into one leaf (four packets).
///
/// The paper's BVH2 has small leaves (1.8 triangles on average on dragon_box, SAH with equal
/// node and triangle costs), and each leaf visit is a cache miss on its packet; testing up
/// to 16 triangles four at a time is cheaper than descending two more node levels. Chosen
/// by measuring 0, 4, 8, 12, 16, 24 and 32 on dragon_box and sponza_dabrovic (16 fastest on
/// dragon_box, all within a few per cent on Sponza), and again once leaves started at a
/// packet's first lane where that saves a packet (4 and 8 fewer instructions but 5–13 %
/// slower on dragon_box; docs/cpu-traversal.md, Experiments); docs/performance.md ("Leaf
/// merging") compares 0 with 16. Answers do not depend on it.
pub const MERGE_MAX: usize = 16;

/// The largest merge limit [`merge_limit`] accepts from the environment.
pub const MERGE_LIMIT_MAX: usize = 64;

/// The merge limit the copies use: [`MERGE_MAX`], unless the environment variable
/// `DUALSPLIT_MERGE_MAX` holds an integer from 0 to [`MERGE_LIMIT_MAX`] (for measuring; 0
/// keeps the image's leaves, the ones a DST converted from the same BVH2 has). Read once; a
/// malformed value keeps [`MERGE_MAX`] here ([`merge_limit_from_env`] reports it).
pub fn merge_limit() -> usize {
    static LIMIT: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *LIMIT.get_or_init(|| merge_limit_from_env().unwrap_or(MERGE_MAX))
}

/// The merge limit `DUALSPLIT_MERGE_MAX` asks for ([`MERGE_MAX`] when unset), or an error
/// naming the variable, its value and what is accepted (the CLI refuses to run with one).
pub fn merge_limit_from_env() -> Result<usize, String> {
    parse_merge_limit(std::env::var("DUALSPLIT_MERGE_MAX").ok().as_deref())
}

/// [`merge_limit_from_env`] for the variable's value `value` (`None`: unset).
fn parse_merge_limit(value: Option<&str>) -> Result<usize, String> {
    let Some(v) = value else { return Ok(MERGE_MAX) };
    match v.trim().parse::<usize>() {
        Ok(n) if n <= MERGE_LIMIT_MAX => Ok(n),
        _ => Err(format!(
            "DUALSPLIT_MERGE_MAX is {v:?}: it must be an integer from 0 to {MERGE_LIMIT_MAX}"
        )),
    }
}

/// The index entries of the leaves of the subtree whose node is at image word `w` (a node's
/// leaves, then its internal children's subtrees in child order), [`RUN_END`] on the last
/// one only; `None` when there are more
/// than `limit`. Iterative: a saved tree may hold long chains of nodes.
pub(super) fn gather<L: NodeLayout>(words: &[u32], w: usize, limit: usize) -> Option<Vec<u32>> {
    let mut out = Vec::new();
    let mut todo = vec![w];
    while let Some(w) = todo.pop() {
        let node = L::read(words, w);
        let mut addr = node.offset() as usize;
        let mut inner = Vec::new();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            match kind {
                ChildKind::Empty => continue,
                ChildKind::Leaf => {
                    let run = words[addr] as usize;
                    for &e in &words[run..] {
                        out.push(e & !RUN_END);
                        if e & RUN_END != 0 || out.len() > limit {
                            break;
                        }
                    }
                }
                ChildKind::Internal => inner.push(addr),
            }
            if out.len() > limit {
                return None;
            }
            addr += L::child_words(kind) as usize;
        }
        todo.extend(inner.into_iter().rev());
    }
    if let Some(last) = out.last_mut() {
        *last |= RUN_END;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_limit_values_are_checked() {
        assert_eq!(parse_merge_limit(None), Ok(MERGE_MAX));
        assert_eq!(parse_merge_limit(Some("0")), Ok(0));
        assert_eq!(parse_merge_limit(Some(" 16 ")), Ok(16));
        assert_eq!(parse_merge_limit(Some("64")), Ok(MERGE_LIMIT_MAX));
        for bad in ["65", "-1", "", "sixteen", "1e3"] {
            let e = parse_merge_limit(Some(bad)).unwrap_err();
            assert!(e.contains("from 0 to 64"), "{bad}: {e}");
        }
    }
}
