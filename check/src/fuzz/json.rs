//! Structure-aware mutation of JSON documents (scene descriptions, glTF): the document is
//! parsed, one value is picked (preferring the keys a target names, such as `count` or
//! `radiance`) and replaced by an edge value that JSON values cannot hold (`NaN`, `1e39`,
//! a 100 000-element array, 300 nested arrays), by `-1` or a huge integer, by another
//! value of the document, or removed; arrays get elements duplicated.

use super::mutate::{FuzzRng, number_replacement};
use rand::Rng;
use serde_json::Value;

/// A string no document contains, replaced by raw text after serialising.
const PLACEHOLDER: &str = "\u{1}FUZZ\u{1}";
/// How `PLACEHOLDER` looks once serialised.
const PLACEHOLDER_SERIALISED: &str = "\"\\u0001FUZZ\\u0001\"";

/// Raw JSON (or not quite JSON) texts put in place of a value.
fn edge_text(rng: &mut FuzzRng) -> String {
    match rng.random_range(0..22) {
        0 => "NaN".into(),
        1 => "1e39".into(),
        2 => "-1e39".into(),
        3 => "-1".into(),
        4 => "0".into(),
        5 => "4294967296".into(),
        6 => "18446744073709551615".into(),
        7 => "1e308".into(),
        8 => "-0.0".into(),
        9 => "null".into(),
        10 => "true".into(),
        11 => "\"\"".into(),
        12 => "[]".into(),
        13 => "{}".into(),
        14 => format!("[{}]", vec!["1e39"; 1000].join(",")),
        15 => format!("[{}]", vec!["0"; 100_000].join(",")),
        16 => format!("{}1{}", "[".repeat(300), "]".repeat(300)),
        17 => "\"../../../../etc/passwd\"".into(),
        18 => "\"\\ud800\"".into(),
        19 => "2147483648".into(),
        20 => "1e-45".into(),
        _ => "[1e39, -1e39, 1e39]".into(),
    }
}

/// JSON pointers of every value in `value` (the root included), and whether the key
/// of each is one of `focus`.
fn pointers(value: &Value, prefix: String, focus: &[&str], out: &mut Vec<(String, bool)>) {
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                let escaped = key.replace('~', "~0").replace('/', "~1");
                let pointer = format!("{prefix}/{escaped}");
                out.push((pointer.clone(), focus.contains(&key.as_str())));
                pointers(child, pointer, focus, out);
            }
        }
        Value::Array(items) => {
            for (index, child) in items.iter().enumerate() {
                let pointer = format!("{prefix}/{index}");
                out.push((pointer.clone(), false));
                pointers(child, pointer, focus, out);
            }
        }
        _ => {}
    }
}

/// One structure-aware mutation of the JSON text `input`; `None` if it is not JSON.
pub fn mutate_json(rng: &mut FuzzRng, input: &[u8], focus: &[&str]) -> Option<Vec<u8>> {
    let mut document: Value = serde_json::from_slice(input).ok()?;
    let mut all = Vec::new();
    pointers(&document, String::new(), focus, &mut all);
    if all.is_empty() {
        return None;
    }
    let focused: Vec<&String> = all.iter().filter(|(_, f)| *f).map(|(p, _)| p).collect();
    let pointer = if !focused.is_empty() && rng.random_bool(0.7) {
        focused[rng.random_range(0..focused.len())].clone()
    } else {
        all[rng.random_range(0..all.len())].0.clone()
    };
    let mut raw = None;
    match rng.random_range(0..8) {
        0..=2 => {
            raw = Some(edge_text(rng));
            *document.pointer_mut(&pointer)? = Value::String(PLACEHOLDER.into());
        }
        3 => {
            let target = document.pointer_mut(&pointer)?;
            let text = target.to_string();
            if target.is_number() {
                raw = Some(number_replacement(rng, text.as_bytes()));
                *target = Value::String(PLACEHOLDER.into());
            } else if let Value::Array(items) = target
                && !items.is_empty()
            {
                let i = rng.random_range(0..items.len());
                let copy = items[i].clone();
                items.insert(i, copy);
            }
        }
        4 => {
            // Remove the value from its parent.
            let (parent, key) = pointer.rsplit_once('/')?;
            match document.pointer_mut(parent)? {
                Value::Object(map) => {
                    map.remove(&key.replace("~1", "/").replace("~0", "~"));
                }
                Value::Array(items) => {
                    let index: usize = key.parse().ok()?;
                    if index < items.len() {
                        items.remove(index);
                    }
                }
                _ => {}
            }
        }
        5 => {
            // Another value of the document in its place.
            let (other, _) = &all[rng.random_range(0..all.len())];
            let copy = document.pointer(other)?.clone();
            *document.pointer_mut(&pointer)? = copy;
        }
        6 => {
            let target = document.pointer_mut(&pointer)?;
            *target = match target {
                Value::Number(n) => {
                    let v = n.as_f64().unwrap_or(0.0);
                    serde_json::json!(if rng.random() { (v * 2.0 + 1.0).round() } else { -v })
                }
                Value::String(_) => {
                    Value::String(["", "x", "a/b", "%", "data:", "\u{0}"][rng.random_range(0..6)].into())
                }
                Value::Array(items) => Value::Array(items.iter().rev().cloned().collect()),
                Value::Bool(b) => Value::Bool(!*b),
                _ => Value::Null,
            };
        }
        _ => {
            if let Value::Object(map) = document.pointer_mut(&pointer)? {
                map.insert("fuzz".into(), Value::from(1));
            } else {
                raw = Some(edge_text(rng));
                *document.pointer_mut(&pointer)? = Value::String(PLACEHOLDER.into());
            }
        }
    }
    let text = if rng.random_bool(0.5) {
        serde_json::to_string(&document).ok()?
    } else {
        serde_json::to_string_pretty(&document).ok()?
    };
    Some(match raw {
        Some(raw) => text.replacen(PLACEHOLDER_SERIALISED, &raw, 1).into_bytes(),
        None => text.into_bytes(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn a_mutated_document_differs_and_stays_mostly_json() {
        let mut rng = FuzzRng::seed_from_u64(1);
        let input = br#"{"a": {"count": 3, "b": [1, 2]}, "c": "x"}"#;
        let mut changed = 0;
        for _ in 0..200 {
            let out = mutate_json(&mut rng, input, &["count"]).unwrap();
            changed += usize::from(out != input);
            assert!(!String::from_utf8_lossy(&out).contains("FUZZ"));
        }
        assert!(changed > 150, "{changed}");
        assert!(mutate_json(&mut rng, b"not json", &[]).is_none());
    }
}
