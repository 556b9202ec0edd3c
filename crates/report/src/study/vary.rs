//! `--vary KEY=V1,V2,...`: one key of the hardware config TOML (dotted: `l1.size_bytes`,
//! `units.dst_pipes`, `dram.t_cas`, `tms`) and the values it takes. A value is set in the
//! TOML table of a configuration and the result deserialized and validated exactly as a
//! `--config` file is, so a sweep can only produce configurations a file could.

use super::StudyError;
use dualsplit_sim::SimConfig;
use serde::{Deserialize, Serialize};

/// Most values of one swept key (`--vary KEY=V1,V2,...`); the plan as a whole is bounded
/// by [`MAX_PLAN_ENTRIES`](super::plan::MAX_PLAN_ENTRIES).
pub const MAX_VARY_VALUES: usize = 1024;

/// One swept key and its values, in the order given.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vary {
    /// Dotted key of the config TOML.
    pub key: String,
    /// Its values, as TOML values.
    pub values: Vec<toml::Value>,
}

impl Vary {
    /// Parses `KEY=V1,V2,...`; each value is read as a TOML value (`32768`, `1.5`, `true`,
    /// `"text"`); the key must exist in `base`'s TOML table.
    pub fn parse(arg: &str, base: &SimConfig) -> Result<Self, StudyError> {
        let err = |reason: String| StudyError::Vary {
            arg: arg.to_string(),
            reason,
        };
        let (key, list) = arg
            .split_once('=')
            .ok_or_else(|| err("expected KEY=V1,V2,... (e.g. l1.size_bytes=32768,65536)".into()))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(str::is_empty) {
            return Err(err("empty key".into()));
        }
        let table = to_table(base).map_err(err)?;
        let current = lookup(&table, key).ok_or_else(|| {
            err(format!(
                "`{key}` is not a key of the config TOML (keys: {})",
                leaf_keys(&table).join(", ")
            ))
        })?;
        if current.is_table() {
            return Err(err(format!(
                "`{key}` is a table; name one of its keys ({})",
                leaf_keys(&table)
                    .into_iter()
                    .filter(|k| k.starts_with(&format!("{key}.")))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let count = list.split(',').count();
        if count > MAX_VARY_VALUES {
            return Err(err(format!(
                "{count} values; at most {MAX_VARY_VALUES} for one key"
            )));
        }
        let mut values = Vec::new();
        for raw in list.split(',') {
            let raw = raw.trim();
            if raw.is_empty() {
                return Err(err("an empty value".into()));
            }
            let v = parse_value(raw).map_err(|e| err(format!("value `{raw}`: {e}")))?;
            if values.contains(&v) {
                return Err(err(format!("value `{raw}` is listed twice")));
            }
            values.push(v);
        }
        Ok(Self {
            key: key.to_string(),
            values,
        })
    }
}

/// A TOML value from its text; bare words that are not TOML (`fast`) are strings.
fn parse_value(raw: &str) -> Result<toml::Value, String> {
    let doc = format!("v = {raw}");
    match toml::from_str::<toml::Table>(&doc) {
        Ok(mut t) => t.remove("v").ok_or_else(|| "not a value".to_string()),
        Err(_)
            if raw
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') =>
        {
            Ok(toml::Value::String(raw.to_string()))
        }
        Err(e) => Err(e.message().to_string()),
    }
}

fn to_table(cfg: &SimConfig) -> Result<toml::Table, String> {
    toml::Table::try_from(cfg).map_err(|e| format!("the configuration as TOML: {e}"))
}

fn lookup<'a>(table: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let mut parts = key.split('.');
    let mut v = table.get(parts.next()?)?;
    for p in parts {
        v = v.as_table()?.get(p)?;
    }
    Some(v)
}

/// Every non-table key of `table`, dotted, in table order.
fn leaf_keys(table: &toml::Table) -> Vec<String> {
    let mut out = Vec::new();
    for (k, v) in table {
        match v.as_table() {
            Some(t) => out.extend(leaf_keys(t).into_iter().map(|s| format!("{k}.{s}"))),
            None => out.push(k.clone()),
        }
    }
    out
}

/// `base` with each `(key, value)` set, deserialized with the config file's rules (unknown
/// keys and wrong types refused) and validated. An integer given for a float key is taken
/// as that float.
pub fn apply(base: &SimConfig, set: &[(String, toml::Value)]) -> Result<SimConfig, StudyError> {
    let combo = describe(set);
    let invalid = |reason: String| StudyError::Vary {
        arg: combo.clone(),
        reason,
    };
    let mut table = to_table(base).map_err(invalid)?;
    for (key, value) in set {
        let mut parts: Vec<&str> = key.split('.').collect();
        let last = parts.pop().unwrap_or_default();
        let mut t = &mut table;
        for p in parts {
            t = t
                .get_mut(p)
                .and_then(toml::Value::as_table_mut)
                .ok_or_else(|| invalid(format!("`{key}` is not a key of the config TOML")))?;
        }
        let slot = t
            .get_mut(last)
            .ok_or_else(|| invalid(format!("`{key}` is not a key of the config TOML")))?;
        *slot = match (&*slot, value) {
            (toml::Value::Float(_), toml::Value::Integer(i)) => toml::Value::Float(*i as f64),
            _ => value.clone(),
        };
    }
    let cfg: SimConfig = toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| invalid(e.message().to_string()))?;
    cfg.validate().map_err(|source| StudyError::Config {
        combo: combo.clone(),
        source,
    })?;
    Ok(cfg)
}

/// `key=value, key=value` (`base` when empty).
pub fn describe(set: &[(String, toml::Value)]) -> String {
    if set.is_empty() {
        return "base".into();
    }
    set.iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The cross product of the sweeps, first key slowest: every combination as `(key, value)`
/// pairs in the sweeps' order. One empty combination when there is no sweep.
pub fn cross_product(vary: &[Vary]) -> Vec<Vec<(String, toml::Value)>> {
    let mut combos: Vec<Vec<(String, toml::Value)>> = vec![Vec::new()];
    for v in vary {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                v.values.iter().map(move |x| {
                    let mut c = c.clone();
                    c.push((v.key.clone(), x.clone()));
                    c
                })
            })
            .collect();
    }
    combos
}

/// A TOML value as a number for a chart axis (booleans as 0 and 1); `None` for text.
pub fn as_number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) => Some(*f),
        toml::Value::Boolean(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_a_dotted_key_and_validates() {
        let base = SimConfig::lin2020();
        let v = Vary::parse("l1.size_bytes=32768,131072", &base).unwrap();
        assert_eq!(v.values.len(), 2);
        let cfg = apply(&base, &[(v.key.clone(), v.values[0].clone())]).unwrap();
        assert_eq!(cfg.l1.size_bytes, 32768);
        assert_eq!(cfg.l2, base.l2);
        let cfg = apply(&base, &[("clock_ghz".into(), toml::Value::Integer(2))]).unwrap();
        assert_eq!(cfg.clock_ghz, 2.0);
    }

    #[test]
    fn refuses_unknown_keys_bad_types_and_invalid_values() {
        let base = SimConfig::lin2020();
        assert!(Vary::parse("l1.size=1,2", &base).is_err());
        assert!(Vary::parse("l1=1,2", &base).is_err());
        assert!(Vary::parse("l1.size_bytes", &base).is_err());
        assert!(Vary::parse("l1.size_bytes=1,,2", &base).is_err());
        assert!(Vary::parse("l1.size_bytes=1,1", &base).is_err());
        let v = Vary::parse("units.dst_pipes=fast", &base).unwrap();
        assert!(apply(&base, &[(v.key, v.values[0].clone())]).is_err());
        // Not a power-of-two set count: refused by the config's own validation.
        let e = apply(
            &base,
            &[("l1.size_bytes".into(), toml::Value::Integer(3000))],
        );
        assert!(matches!(e, Err(StudyError::Config { .. })), "{e:?}");
    }

    #[test]
    fn cross_product_has_every_combination_once() {
        let base = SimConfig::lin2020();
        let a = Vary::parse("units.dst_pipes=1,2,4", &base).unwrap();
        let b = Vary::parse("l1.banks=8,16", &base).unwrap();
        let c = cross_product(&[a, b]);
        assert_eq!(c.len(), 6);
        let mut seen: Vec<String> = c.iter().map(|x| describe(x)).collect();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 6);
        assert_eq!(cross_product(&[]), vec![Vec::new()]);
    }
}
