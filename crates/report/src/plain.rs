//! `Result<T, String>` fields as plain JSON: a value that was measured is written as the
//! value itself (`"bytes": 850708`), one that could not be is `{"error": "why"}`. Use as
//! `#[serde(with = "crate::plain")]`.
//!
//! Reading also accepts serde's default `{"Ok": v}` / `{"Err": "why"}` form, so values
//! written in that form (older cached pieces) still load.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Why a value is missing, as written.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Missing<E> {
    error: E,
}

/// serde's default externally tagged form of a `Result`.
#[derive(Deserialize)]
enum Tagged<T, E> {
    Ok(T),
    Err(E),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Repr<T, E> {
    Tagged(Tagged<T, E>),
    Missing(Missing<E>),
    Plain(T),
}

/// Writes `Ok(v)` as `v` and `Err(e)` as `{"error": e}`.
pub fn serialize<T: Serialize, E: Serialize, S: Serializer>(
    v: &Result<T, E>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match v {
        Ok(v) => v.serialize(s),
        Err(e) => Missing { error: e }.serialize(s),
    }
}

/// Reads what [`serialize`] writes, or serde's default form of a `Result`.
pub fn deserialize<'de, T, E, D>(d: D) -> Result<Result<T, E>, D::Error>
where
    T: Deserialize<'de>,
    E: Deserialize<'de>,
    D: Deserializer<'de>,
{
    Ok(match Repr::<T, E>::deserialize(d)? {
        Repr::Tagged(Tagged::Ok(v)) | Repr::Plain(v) => Ok(v),
        Repr::Tagged(Tagged::Err(e)) | Repr::Missing(Missing { error: e }) => Err(e),
    })
}

#[cfg(test)]
mod tests {
    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct S {
        #[serde(with = "super")]
        n: Result<u64, String>,
        #[serde(with = "super")]
        x: Result<f64, String>,
    }

    #[test]
    fn values_are_written_plain_and_read_back() {
        let v = S {
            n: Ok(850_708),
            x: Err("not built".into()),
        };
        let text = serde_json::to_string(&v).unwrap();
        assert_eq!(text, r#"{"n":850708,"x":{"error":"not built"}}"#);
        assert_eq!(serde_json::from_str::<S>(&text).unwrap(), v);
        let old = r#"{"n":{"Ok":850708},"x":{"Err":"not built"}}"#;
        assert_eq!(serde_json::from_str::<S>(old).unwrap(), v);
        assert!(serde_json::from_str::<S>(r#"{"n":"x","x":1.5}"#).is_err());
    }
}
