//! A TOML file's parse and type errors in its reader's words, for every TOML file a user
//! writes (presets, jobs files): where the error is (line and column), which dotted key it
//! is under, and what is accepted without serde's Rust type names. serde's message for
//! `seed = "x"` is `invalid type: string "x", expected u64`; here it is ``key `seed`: invalid
//! type: string "x", expected a whole number``.

use toml::de::{DeTable, DeValue};

/// A TOML error located in its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Described {
    /// 1-based line and column where the error's span starts, when it has one.
    pub line_column: Option<(usize, usize)>,
    pub message: String,
}

/// `error`, met while reading `text`, located and in plain words: a duplicate key named, an
/// unknown key with the nearest accepted one, and a value of the wrong type or variant with
/// the dotted key it is written under.
pub fn describe(text: &str, error: &toml::de::Error) -> Described {
    let span = error.span();
    let mut message = in_plain_words(error.message().trim_end());
    if message.contains("duplicate key") {
        if !message.contains('`') {
            // Name the key: the span of a duplicate-key error covers it.
            let key = span.clone().and_then(|s| text.get(s)).map(str::trim).filter(|k| !k.is_empty());
            if let Some(key) = key {
                message = format!("duplicate key `{key}`: each key may appear once per table");
            }
        }
    } else if !message.starts_with("unknown key")
        && let Some(key) = span.clone().and_then(|s| key_at(text, s.start))
    {
        message = format!("key `{key}`: {message}");
    }
    Described { line_column: span.map(|s| line_column(text, s.start)), message }
}

/// serde's message in a reader's words: "unknown field" with the nearest accepted key, and
/// Rust's type names (`expected u32`, `expected struct Scales`) as what they accept.
pub fn in_plain_words(message: &str) -> String {
    with_suggestion(&plain_type_names(message))
}

/// 1-based line and column of a byte offset.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |s| s.chars().count()) + 1;
    (line, column)
}

/// Rewrites serde's "unknown field `x`, expected one of `a`, `b`" into a message that names
/// the key, suggests the nearest accepted one, and lists them all.
fn with_suggestion(message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_string();
    };
    let Some((unknown, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    let accepted: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let nearest = accepted
        .iter()
        .map(|a| (crate::preset::edit_distance(unknown, a), *a))
        .filter(|(d, a)| *d <= 2.max(a.len() / 3))
        .min();
    let hint = nearest.map(|(_, a)| format!("; did you mean `{a}`?")).unwrap_or_default();
    format!("unknown key `{unknown}`{hint} (accepted keys here: {})", accepted.join(", "))
}

/// `expected u32` → `expected a whole number`, `expected struct Scales` → `expected a table`.
fn plain_type_names(message: &str) -> String {
    let mut out = message.to_string();
    for (rust, plain) in [
        ("u8", "a whole number"),
        ("u16", "a whole number"),
        ("u32", "a whole number"),
        ("u64", "a whole number"),
        ("usize", "a whole number"),
        ("i32", "an integer"),
        ("i64", "an integer"),
        ("f32", "a number"),
        ("f64", "a number"),
        ("a sequence", "an array"),
    ] {
        let rust = format!("expected {rust}");
        let mut from = 0;
        while let Some(at) = out[from..].find(&rust).map(|i| i + from) {
            let end = at + rust.len();
            // `expected u32` but not `expected u320`.
            if out[end..].starts_with(|c: char| c.is_alphanumeric() || c == '_') {
                from = end;
                continue;
            }
            out.replace_range(at..end, &format!("expected {plain}"));
            from = at;
        }
    }
    if let Some(at) = out.find("expected struct ") {
        let name = at + "expected struct ".len();
        let end = out[name..].find(|c: char| !(c.is_alphanumeric() || c == '_')).map_or(out.len(), |i| name + i);
        out.replace_range(at..end, "expected a table");
    }
    out
}

/// The dotted key (`scales.rows`, `pattern.1.colors.0`) whose value is written over byte
/// `offset` of `text`: the key a type error's span points into.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let root = DeTable::parse(text).ok()?;
    key_in_table(root.get_ref(), offset)
}

fn key_in_table(table: &DeTable, offset: usize) -> Option<String> {
    table.iter().find_map(|(key, value)| Some(joined(key.get_ref(), key_in_value(value, offset)?)))
}

/// `Some("")` when `value` itself is written over `offset` and no value inside it is, the
/// dotted rest when one inside it is, `None` otherwise.
fn key_in_value(value: &toml::Spanned<DeValue>, offset: usize) -> Option<String> {
    let inner = match value.get_ref() {
        DeValue::Table(t) => key_in_table(t, offset),
        DeValue::Array(items) => {
            items.iter().enumerate().find_map(|(i, item)| Some(joined(&i.to_string(), key_in_value(item, offset)?)))
        }
        _ => None,
    };
    inner.or_else(|| value.span().contains(&offset).then(String::new))
}

fn joined(key: &str, rest: String) -> String {
    if rest.is_empty() { key.to_string() } else { format!("{key}.{rest}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whole type names only: a name that merely starts like one is left alone.
    #[test]
    fn type_names_are_replaced_whole() {
        assert_eq!(
            plain_type_names("invalid type: string \"x\", expected u64"),
            "invalid type: string \"x\", expected a whole number"
        );
        assert_eq!(plain_type_names("expected u320 or expected f64"), "expected u320 or expected a number");
        assert_eq!(
            plain_type_names("invalid type: integer `5`, expected struct Scales"),
            "invalid type: integer `5`, expected a table"
        );
    }
}
