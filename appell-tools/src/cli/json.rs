//! Reading JSON strictly: serde_json keeps the last of two equal keys
//! silently, so `{"q": {"x": 1, "x": 2}}` would be read as x = 2. The
//! command line refuses such input instead, at any depth.

use serde::de::{Deserialize, Deserializer, Error as _, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::fmt;

/// Parses `text` as one JSON object; a malformed text, another kind of
/// value or a key repeated in any object is an error that says so.
pub(super) fn parse_object(text: &str) -> Result<Map<String, Value>, String> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value = Strict::deserialize(&mut de)
        .and_then(|v| de.end().map(|()| v.0))
        .map_err(|e| format!("malformed JSON: {e}"))?;
    match value {
        Value::Object(obj) => Ok(obj),
        _ => Err("expected a JSON object".to_string()),
    }
}

/// A JSON value read with every object's keys checked for repeats.
struct Strict(Value);

impl<'de> Deserialize<'de> for Strict {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(StrictVisitor)
    }
}

/// Builds the [`Value`] as serde_json's own visitor does, but for the
/// repeated keys.
struct StrictVisitor;

impl<'de> Visitor<'de> for StrictVisitor {
    type Value = Strict;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Strict, E> {
        Ok(Strict(Value::Bool(v)))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Strict, E> {
        Ok(Strict(Value::from(v)))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Strict, E> {
        Ok(Strict(Value::from(v)))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Strict, E> {
        // serde_json never hands over a non-finite number.
        Ok(Strict(
            serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number),
        ))
    }

    fn visit_str<E>(self, v: &str) -> Result<Strict, E> {
        Ok(Strict(Value::String(v.to_string())))
    }

    fn visit_string<E>(self, v: String) -> Result<Strict, E> {
        Ok(Strict(Value::String(v)))
    }

    fn visit_unit<E>(self) -> Result<Strict, E> {
        Ok(Strict(Value::Null))
    }

    fn visit_none<E>(self) -> Result<Strict, E> {
        Ok(Strict(Value::Null))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Strict, A::Error> {
        let mut items = Vec::new();
        while let Some(Strict(v)) = seq.next_element()? {
            items.push(v);
        }
        Ok(Strict(Value::Array(items)))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Strict, A::Error> {
        let mut obj = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let Strict(value) = map.next_value()?;
            if obj.contains_key(&key) {
                return Err(A::Error::custom(format_args!("duplicate key `{key}`")));
            }
            obj.insert(key, value);
        }
        Ok(Strict(Value::Object(obj)))
    }
}

#[cfg(test)]
mod tests {
    use super::parse_object;

    #[test]
    fn a_repeated_key_is_an_error_at_any_depth() {
        for text in [
            r#"{"t": 0, "t": 1}"#,
            r#"{"q": {"x": 1, "x": 2}}"#,
            r#"{"connectors": [["O", "a"], {"b": 1, "b": 1}]}"#,
            // The same key spelled with an escape.
            r#"{"q": {"x": 1, "\u0078": 2}}"#,
        ] {
            let err = parse_object(text).unwrap_err();
            assert!(err.contains("duplicate key `"), "{text}: {err}");
        }
        let err = parse_object(r#"{"q": {"phi": 1, "phi": 2}}"#).unwrap_err();
        assert!(
            err.starts_with("malformed JSON: duplicate key `phi`"),
            "{err}"
        );
    }

    #[test]
    fn everything_else_reads_as_serde_json_reads_it() {
        let text = r#"{"t": -0.5, "n": 18446744073709551615, "i": -3, "s": "\u00e9",
                       "b": [true, null, 1e300, {"x": 1}], "q": {"x": 1, "y": 2}, "e": {}}"#;
        let strict = serde_json::Value::Object(parse_object(text).unwrap());
        let loose: serde_json::Value = serde_json::from_str(text).unwrap();
        assert_eq!(strict, loose);
        // Equal keys in different objects are fine.
        assert!(parse_object(r#"{"q": {"x": 1}, "u": {"x": 2}}"#).is_ok());
    }

    #[test]
    fn malformed_text_and_other_values_are_errors() {
        assert!(parse_object("{\"t\": 0")
            .unwrap_err()
            .starts_with("malformed JSON"));
        assert!(parse_object("{} {}")
            .unwrap_err()
            .starts_with("malformed JSON"));
        assert_eq!(parse_object("[1]").unwrap_err(), "expected a JSON object");
    }
}
