//! A pretty JSON layout that keeps arrays of plain values on one line, so the
//! `lut.json` of a 95-wavelength bake stays readable (serde_json's pretty printer puts
//! every number of every `[wavelength, n]` pair on its own line).

use serde_json::Value;

/// `value` as indented JSON with two-space indents; scalar-only arrays stay inline.
pub(crate) fn to_pretty_string(value: &Value) -> String {
    let mut out = String::new();
    write_value(value, 0, &mut out);
    out.push('\n');
    out
}

fn write_value(value: &Value, depth: usize, out: &mut String) {
    match value {
        Value::Object(map) if !map.is_empty() => {
            out.push('{');
            for (k, (key, item)) in map.iter().enumerate() {
                out.push_str(if k == 0 { "\n" } else { ",\n" });
                indent(depth + 1, out);
                out.push_str(&Value::String(key.clone()).to_string());
                out.push_str(": ");
                write_value(item, depth + 1, out);
            }
            out.push('\n');
            indent(depth, out);
            out.push('}');
        }
        Value::Array(items)
            if items
                .iter()
                .any(|v| v.is_object() || v.is_array() && !inline(v)) =>
        {
            out.push('[');
            for (k, item) in items.iter().enumerate() {
                out.push_str(if k == 0 { "\n" } else { ",\n" });
                indent(depth + 1, out);
                write_value(item, depth + 1, out);
            }
            out.push('\n');
            indent(depth, out);
            out.push(']');
        }
        Value::Array(items) => {
            out.push('[');
            for (k, item) in items.iter().enumerate() {
                if k > 0 {
                    out.push_str(", ");
                }
                write_value(item, depth, out);
            }
            out.push(']');
        }
        scalar => out.push_str(&scalar.to_string()),
    }
}

/// Whether an array holds only scalars (or is empty), and so is written on one line.
fn inline(value: &Value) -> bool {
    value
        .as_array()
        .is_some_and(|items| items.iter().all(|v| !v.is_object() && !v.is_array()))
}

fn indent(depth: usize, out: &mut String) {
    for _ in 0..depth {
        out.push_str("  ");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_inlines_number_pairs() {
        let value = serde_json::json!({
            "a": [[360.0, 1.33], [365.0, 1.34]],
            "b": {"c": "x\"y", "d": [], "e": {}},
            "f": [{"g": 1}],
            "h": -0.0
        });
        let text = to_pretty_string(&value);
        assert!(text.contains("[360.0, 1.33]"), "{text}");
        let back: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, value);
    }
}
