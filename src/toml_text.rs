//! A TOML file's parse and type errors in its reader's words, for every TOML file a user
//! writes (presets, jobs files): where the error is (line and column), which dotted key it
//! is under, and what is accepted without serde's Rust type names. serde's message for
//! `seed = "x"` is `invalid type: string "x", expected u64`; here it is ``key `seed`: invalid
//! type: string "x", expected a whole number``.

use std::ops::Range;

use toml::de::{DeTable, DeValue};

/// A TOML error located in its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Described {
    /// 1-based line and column where the error's span starts, when it has one.
    pub line_column: Option<(usize, usize)>,
    /// The dotted key (`scales.rows`, `job.0.sizes`) of a value of the wrong type or
    /// variant, for the caller to name as its readers count (a jobs file says "[[job]] 1").
    pub key: Option<String>,
    pub message: String,
}

impl Described {
    /// The message with its key, if any: ``key `scales.rows`: invalid type: ...``.
    pub fn keyed_message(&self) -> String {
        match &self.key {
            Some(key) => format!("key `{key}`: {}", self.message),
            None => self.message.clone(),
        }
    }
}

/// `error`, met while reading `text`, located and in plain words: a duplicate key named, an
/// unknown key with the nearest accepted one, and for a value of the wrong type or variant
/// the dotted key it is written under.
pub fn describe(text: &str, error: &toml::de::Error) -> Described {
    let span = error.span();
    let mut message = in_plain_words(error.message().trim_end());
    // toml hands a date or time over as a table of its own: say what was written.
    let written = span.clone().and_then(|s| text.get(s)).map(str::trim);
    if message.starts_with("invalid type: table") && written.is_some_and(|v| v.parse::<toml::value::Datetime>().is_ok())
    {
        message = message.replacen("invalid type: table", "invalid type: a date or time", 1);
    }
    let mut at = span.as_ref().map(|s| s.start);
    // A key that looks right but holds a look-alike (a Cyrillic `а` in `scаles`, a
    // non-breaking space): the reader's "invalid unquoted key" does not say which character.
    let refused = span.as_ref().and_then(|s| text.get(s.start..)).and_then(|rest| rest.chars().next());
    if message.starts_with("invalid unquoted key")
        && let Some(c) = refused.filter(|c| !c.is_ascii())
    {
        message = format!(
            "{message} (ASCII only); `{c}` (U+{:04X}) is not ASCII, though it may look like a letter",
            c as u32
        );
    }
    if message == "recursion limit" || message.starts_with("cannot recurse further") {
        message = format!(
            "keys, tables or arrays nested more than {TOML_NESTING_LIMIT} levels deep (no key of a preset or jobs file \
             is nested more than a few)"
        );
        // The parser gives a dotted key's depth no span: find the line that is that deep.
        at = at.or_else(|| too_deep_line(text));
    }
    // A raw control character (a NUL, an escape) is allowed nowhere in TOML text, but the
    // reader says what it expected there: `seed = 1<NUL>` was "string values must be quoted".
    if let Some(offset) = at
        && let Some((control_at, c)) = control_on_line(text, offset)
    {
        message = format!(
            "the control character U+{:04X} is not allowed in TOML text (inside a double-quoted string, write it \
             as the escape `\\u{:04X}`; a comment cannot hold one)",
            c as u32, c as u32
        );
        at = Some(control_at);
    }
    let mut key = None;
    if message.contains("duplicate key") {
        if !message.contains('`') {
            // Name the key: the span of a duplicate-key error covers it.
            let written = span.clone().and_then(|s| text.get(s)).map(str::trim).filter(|k| !k.is_empty());
            if let Some(written) = written {
                message = format!("duplicate key `{written}`: each key may appear once per table");
            }
        }
    } else if !message.starts_with("unknown key") {
        key = span.clone().and_then(|s| key_at(text, s.start));
        // An array of tables where one table belongs (`[[scales]]`): the reader points at the
        // header, whose key is the array's first element (`scales.0`); the array is at fault.
        // Only a header that names that array (an inline `[[1]]` item is the item's fault).
        if message.starts_with("invalid type: array, expected a table")
            && let Some((array, index)) = key.as_deref().and_then(|k| k.rsplit_once('.'))
            && index.bytes().all(|b| b.is_ascii_digit())
            && written
                .and_then(|w| w.strip_prefix("[[")?.split_once("]]"))
                .is_some_and(|(name, _)| name.trim() == array)
        {
            key = Some(array.to_string());
        }
    }
    Described { line_column: at.map(|offset| line_column(text, offset)), key, message }
}

/// How deep the TOML reader nests keys, tables and arrays before it refuses a file: the
/// `LIMIT` of toml 0.9's parser (`de/parser/mod.rs`). A `--set` key is held to it too
/// (`preset::load`): split at its dots, it never reaches the reader's count.
pub const TOML_NESTING_LIMIT: usize = 80;

/// The offset of the first line whose key has more than `TOML_NESTING_LIMIT` dotted parts
/// (the reader takes 80 and refuses 81; quoted dots counted too, comments skipped: a close
/// enough guess for a line the reader gave none).
fn too_deep_line(text: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let key = line.split('=').next().unwrap_or(line);
        if !line.trim_start().starts_with('#') && key.matches('.').count() + 1 > TOML_NESTING_LIMIT {
            return Some(offset);
        }
        offset += line.len();
    }
    None
}

/// The first control character TOML forbids (U+0000–U+001F but tab, line feed and carriage
/// return, and U+007F: TOML 1.0 and 1.1, "Comment" and "String") from `offset`, where the
/// reader's error starts, or the run of them just before it (a line that starts with some:
/// the reader points past the first, "key with no value", at the last: `\u{1}\u{1}` was
/// reported at column 2), to the end of its line, with its offset.
/// One further before the error, or on another line, is not what the reader refused there.
/// A carriage return out of place is left to the reader's own message.
fn control_on_line(text: &str, offset: usize) -> Option<(usize, char)> {
    let end = text.get(offset..)?.find('\n').map_or(text.len(), |i| offset + i);
    let forbidden = |c: char| (c <= '\u{1f}' && !matches!(c, '\t' | '\n' | '\r')) || c == '\u{7f}';
    let run_before: usize = text[..offset].chars().rev().take_while(|c| forbidden(*c)).map(char::len_utf8).sum();
    let start = offset - run_before;
    text[start..end].char_indices().find(|&(_, c)| forbidden(c)).map(|(i, c)| (start + i, c))
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
    // A byte-order mark (an editor's UTF-8 file) is not a column of the first line.
    let last = before.rsplit('\n').next().unwrap_or("");
    let column = if line == 1 { last.trim_start_matches('\u{feff}') } else { last }.chars().count() + 1;
    (line, column)
}

/// Text from a file for a message of one line: every control character, newline included,
/// written as `\u{..}`. A key or a name from a file printed raw could start a line of its
/// own that passes for the tool's (`"a\nFAKE" = 1` printed `FAKE` alone on a line, and a
/// jobs file's `set` a made-up `1/1 done` line: a hostile-input sweep), and every character
/// that reorders text or breaks its lines (`export::reshapes_text`: they were printed raw).
pub fn one_line(text: &str) -> String {
    let hidden = |c: char| c.is_control() || crate::export::reshapes_text(c);
    text.chars().map(|c| if hidden(c) { c.escape_unicode().to_string() } else { c.to_string() }).collect()
}

/// Rewrites serde's "unknown field `x`, expected one of `a`, `b`" into a message that names
/// the key (on one line: `one_line`), suggests the nearest accepted one, and lists them all.
fn with_suggestion(message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return message.to_string();
    };
    let Some((unknown, expected)) = rest.split_once('`') else {
        return message.to_string();
    };
    let accepted: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let hint = nearest(unknown, accepted.iter().copied()).map(|a| format!("; did you mean `{a}`?")).unwrap_or_default();
    format!("unknown key `{}`{hint} (accepted keys here: {})", one_line(unknown), accepted.join(", "))
}

/// Every dotted key an override of `key` with `value` writes: a table's own keys (an
/// override merges a table key by key), a list's entries as `key.N` (`pattern = [{ color =
/// .. }]` beside `"pattern.0.kind"` loses nothing), anything else `key` itself. An empty
/// table or list writes no key of its own.
pub fn written_keys(key: &str, value: &toml::Value) -> Vec<String> {
    fn leaves(key: String, value: &toml::Value, into: &mut Vec<String>) {
        match value {
            toml::Value::Table(t) => {
                for (k, v) in t {
                    leaves(format!("{key}.{k}"), v, into);
                }
            }
            toml::Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    leaves(format!("{key}.{i}"), v, into);
                }
            }
            _ => into.push(key),
        }
    }
    let mut into = Vec::new();
    leaves(key.to_string(), value, &mut into);
    into
}

/// A key that two overrides' written keys (`written_keys`) both reach, the longer of the
/// first pair where one lies within the other (`scales.rows` for `scales = { rows = 25 }` and
/// `"scales.rows" = 23`; `scales.rows` for `scales = 5` beside it): one of the two values is
/// lost. None where they write apart.
pub fn key_written_by_both<'a>(a: &'a [String], b: &'a [String]) -> Option<&'a String> {
    a.iter().find_map(|x| {
        let y = b.iter().find(|y| key_within(x, y) || key_within(y, x))?;
        Some(if x.len() >= y.len() { x } else { y })
    })
}

/// Whether the dotted key `key` is `table` or lies inside it (`scales.rows` in `scales`, not
/// `scales_x`).
pub fn key_within(key: &str, table: &str) -> bool {
    key.strip_prefix(table).is_some_and(|rest| rest.is_empty() || rest.starts_with('.'))
}

/// The accepted name nearest to `unknown`, for "did you mean", if one is near enough: at
/// most 2 edits, or a third of its length for a long one, and at most half its letters for a
/// short one (`graph --maps foo` asked "did you mean ao?": two edits, every letter of `ao`).
/// Case is not an edit (`ROWS` had no suggestion).
pub fn nearest<'a>(unknown: &str, accepted: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let unknown = unknown.to_lowercase();
    accepted
        .into_iter()
        .map(|a| (edit_distance(&unknown, &a.to_lowercase()), a))
        .filter(|(d, a)| *d <= 2.max(a.len() / 3).min(a.chars().count() / 2))
        .min()
        .map(|(_, a)| a)
}

/// Levenshtein distance, for "did you mean".
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The value of a whole number its key's type cannot hold (`-3`, `5000000000`), from a
/// message in plain words (`in_plain_words`: "invalid value: integer `-3`, expected a whole
/// number from 0 to 4294967295"), for the caller to refuse with the key's own range.
pub fn integer_out_of_type(message: &str) -> Option<&str> {
    message.strip_prefix("invalid value: integer `")?.split('`').next()
}

/// serde's words for types in a reader's: what the value is (`invalid type: sequence`) and
/// what is accepted (`expected u32`, `expected struct Scales`). Only serde's own parts are
/// rewritten: the value's type after "invalid type: " and the final ", expected ..."; the value
/// the message quotes only where a float lies beyond the plain range (written out in all its
/// digits), as `validate::shown` shows every refused number. An integer's type range is named
/// only where the value is a whole number outside it (`-1`, `5000000000`): for `rows = 4.0` it
/// read "expected a whole number from 0 to 4294967295", which is not the key's range (4 to
/// 128, checked once the value is a whole number). A whole number beyond i64 is "an integer
/// `…` as i128" in toml's words: said as the value it is.
fn plain_type_names(message: &str) -> String {
    let mut out = message.to_string();
    for (serde, plain) in [("sequence", "array"), ("map", "table")] {
        let from = format!("invalid type: {serde},");
        if out.starts_with(&from) {
            out.replace_range(..from.len(), &format!("invalid type: {plain},"));
        }
    }
    const UNSIGNED: [&str; 5] = ["u8", "u16", "u32", "u64", "usize"];
    if let Some(rest) = out.strip_prefix("invalid type: integer `")
        && let Some((digits, tail)) = rest.split_once("` as i128,")
        && UNSIGNED.iter().any(|u| tail == format!(" expected {u}"))
    {
        out = format!("invalid value: integer `{digits}`,{tail}");
    }
    // A float where a whole number belongs is written out in full (`rows = 1e300`: three
    // hundred digits); beyond the plain range, in exponent form, as every refused number is.
    if let Some(rest) = out.strip_prefix("invalid type: floating point `")
        && let Some((number, tail)) = rest.split_once('`')
        && let Ok(value) = number.parse::<f64>()
        && let shown = crate::preset::validate::shown(value)
        && shown.contains('e')
    {
        out = format!("invalid type: floating point `{shown}`{tail}");
    }
    let Some(at) = out.rfind(", expected ") else { return out };
    let whole_number = out.starts_with("invalid value: integer");
    let expected = &out[at + ", expected ".len()..];
    let plain = match expected {
        unsigned if UNSIGNED.contains(&unsigned) && !whole_number => "a whole number",
        "u8" => "a whole number from 0 to 255",
        "u16" => "a whole number from 0 to 65535",
        "u32" => "a whole number from 0 to 4294967295",
        "u64" | "usize" => "a whole number from 0 to 18446744073709551615",
        "i32" | "i64" => "an integer",
        "f32" | "f64" => "a number",
        "a sequence" => "an array",
        other
            if other
                .strip_prefix("struct ")
                .is_some_and(|name| name.chars().all(|c| c.is_alphanumeric() || c == '_')) =>
        {
            "a table"
        }
        _ => return out,
    };
    out.replace_range(at + ", expected ".len().., plain);
    out
}

/// The lines of dotted keys in one text, parsed once: a jobs file asks for two keys per
/// job, and parsing the file for each made loading it quadratic in its size (and a preset's
/// thousands of problems took minutes).
pub struct KeyLines<'a> {
    root: Option<toml::Spanned<DeTable<'a>>>,
    /// The byte offset where each line starts.
    line_starts: Vec<usize>,
}

impl<'a> KeyLines<'a> {
    pub fn new(text: &'a str) -> KeyLines<'a> {
        let line_starts = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
        KeyLines { root: DeTable::parse(text).ok(), line_starts }
    }

    /// The line of a dotted key (`pattern.1.size`, `job.0.set`), if it is written there; an
    /// index into an array counts its items (`job.2` is the third `[[job]]`), and `NAME.0` of
    /// a single `[NAME]` table is that table (a preset's one `[pattern]` is layer 0).
    pub fn line(&self, dotted: &str) -> Option<usize> {
        let root = self.root.as_ref()?;
        let mut span: Option<Range<usize>> = None;
        let mut value: Option<&DeValue> = None;
        for segment in dotted.split('.') {
            let (key_span, item) = match value {
                None => {
                    root.get_ref().iter().find(|(k, _)| k.get_ref().as_ref() == segment).map(|(k, v)| (k.span(), v))?
                }
                Some(DeValue::Table(t)) if segment == "0" && !t.iter().any(|(k, _)| k.get_ref().as_ref() == "0") => {
                    // `pattern.0` when `pattern` is a single table: the table is layer 0.
                    continue;
                }
                Some(DeValue::Table(t)) => {
                    t.iter().find(|(k, _)| k.get_ref().as_ref() == segment).map(|(k, v)| (k.span(), v))?
                }
                Some(DeValue::Array(items)) => {
                    let item = items.get(segment.parse::<usize>().ok()?)?;
                    (item.span(), item)
                }
                Some(_) => break,
            };
            span = Some(key_span);
            value = Some(item.get_ref());
        }
        // Lines are counted from 1: the number of lines that start at or before the key.
        span.map(|s| self.line_starts.partition_point(|start| *start <= s.start))
    }
}

/// True where `written`, a decimal number as written (a TOML float without its underscores,
/// a flag's value), is not zero but reads as 0: nearer 0 than a 64-bit float holds (about
/// 2.5e-324). Such a number was read as 0 without a word (`between_scales = 1e-400`, even
/// where 0 is out of range: "got 0"), while one too large for a float is refused.
pub fn underflows(written: &str) -> bool {
    let mantissa = written.split(['e', 'E']).next().unwrap_or_default();
    written.trim().parse::<f64>() == Ok(0.0) && mantissa.chars().any(|c| ('1'..='9').contains(&c))
}

/// What is said of a number that underflows (`underflows`), `instead` what to write.
pub fn underflow_message(written: &str, instead: &str) -> String {
    format!(
        "`{}` is nearer 0 than a 64-bit float holds (the nearest is about 5e-324) and would be read as 0: write \
         {instead}",
        written.trim()
    )
}

/// What a key's underflowing number is to be replaced with (`underflow_message`).
pub const UNDERFLOW_INSTEAD: &str = "a number the key accepts (0 itself, where it does)";

/// A float written in `text` that underflows (`underflows`; of several, the first in the
/// order of the keys, which may not be the file's), located and keyed as the reader's errors
/// are (`describe`); `None` where there is none or the text does not parse (the reader's own
/// error then says why).
pub fn underflowing_float(text: &str) -> Option<Described> {
    fn in_value(value: &toml::Spanned<DeValue>) -> Option<(String, Range<usize>, String)> {
        match value.get_ref() {
            DeValue::Float(f) if underflows(f.as_str()) => Some((String::new(), value.span(), f.as_str().to_string())),
            DeValue::Table(t) => in_table(t),
            DeValue::Array(items) => items.iter().enumerate().find_map(|(i, item)| {
                let (key, span, written) = in_value(item)?;
                Some((joined(&i.to_string(), key), span, written))
            }),
            _ => None,
        }
    }
    fn in_table(table: &DeTable) -> Option<(String, Range<usize>, String)> {
        table.iter().find_map(|(key, value)| {
            let (rest, span, written) = in_value(value)?;
            Some((joined(key.get_ref(), rest), span, written))
        })
    }
    let root = DeTable::parse(text).ok()?;
    let (key, span, _) = in_table(root.get_ref())?;
    // The message quotes the number as written, underscores and all.
    let written = text.get(span.clone()).unwrap_or_default();
    Some(Described {
        line_column: Some(line_column(text, span.start)),
        key: Some(key),
        message: underflow_message(written, UNDERFLOW_INSTEAD),
    })
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

    /// What reads as 0 though it is not 0 underflows; 0 however written, the smallest float,
    /// numbers too large and words do not.
    #[test]
    fn underflow_is_a_nonzero_number_read_as_zero() {
        for tiny in ["1e-400", "-1e-400", "+2.5E-330", "0.001e-322", "1e-324", " 3e-999 "] {
            assert!(underflows(tiny), "{tiny}");
        }
        for not in ["0", "-0.0", "0e-400", "0.000E-5", "5e-324", "1e-300", "1e400", "inf", "nan", "e", "", "1e-4x00"] {
            assert!(!underflows(not), "{not}");
        }
        let text = "seed = 1\n[optics]\nabsorption = [0.5, 1_0e-401, 0.0]\n";
        let found = underflowing_float(text).expect("one underflows");
        assert_eq!((found.line_column, found.key.as_deref()), (Some((3, 20)), Some("optics.absorption.1")));
        assert!(found.message.starts_with("`1_0e-401` is nearer 0"), "{}", found.message);
        assert!(underflowing_float("seed = 1\n[optics]\nabsorption = [0.5, 1e-300, 0.0]\n").is_none());
    }

    /// A date where a number goes was called a table (toml's form of a date).
    #[test]
    fn a_date_is_named_a_date() {
        #[derive(Debug, serde::Deserialize)]
        struct Seeded {
            #[allow(dead_code)]
            seed: u64,
        }
        for (text, says) in [("seed = 1979-05-27\n", "a date or time"), ("seed = { a = 1 }\n", "invalid type: table")] {
            let error = toml::from_str::<Seeded>(text).unwrap_err();
            let described = describe(text, &error);
            assert!(
                described.message.starts_with(&format!("invalid type: {}", says.trim_start_matches("invalid type: "))),
                "{text}: {}",
                described.message
            );
        }
    }

    /// A raw control character is named with its own column: `seed = 1<NUL>` was "string
    /// values must be quoted" at the value. Negative control: the escape in a quoted string.
    #[test]
    fn a_control_character_is_named_where_it_is() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct Named {
            name: Option<String>,
            seed: Option<u64>,
        }
        for (text, line_column, code) in [
            ("name = \"x\"\nseed = 1\0\n", (2, 9), "U+0000"),
            ("seed = \u{1b}\n", (1, 8), "U+001B"),
            ("name = \"a\u{7f}b\"\n", (1, 10), "U+007F"),
            ("seed = 1 # a\u{1}\n", (1, 13), "U+0001"),
            // At a line's start the reader points past it ("key with no value" at 2:2).
            ("seed = 7\n\u{1}\n", (2, 1), "U+0001"),
            ("seed = 7\n\u{1}\u{2}\u{1}\n", (2, 1), "U+0001"),
            ("seed = 7\n  \u{2}\u{1}\n", (2, 3), "U+0002"),
            ("\0", (1, 1), "U+0000"),
        ] {
            let error = toml::from_str::<Named>(text).unwrap_err();
            let described = describe(text, &error);
            assert_eq!(described.line_column, Some(line_column), "{text:?}: {}", described.message);
            assert!(described.message.starts_with(&format!("the control character {code} ")), "{}", described.message);
        }
        // The reader's own message where no control character is what it refused: a tab and
        // a carriage return on the error's line, one on a later line.
        for text in ["seed = = 1\t\r\n", "seed = = 1\nname = \"a\u{1}\"\n"] {
            let error = toml::from_str::<Named>(text).unwrap_err();
            let described = describe(text, &error);
            assert!(!described.message.contains("control character"), "{text:?}: {}", described.message);
        }
    }

    /// Nesting past the reader's limit was "recursion limit" with no line for a dotted key,
    /// and "cannot recurse further" for arrays. Negative control: just under the limit.
    #[test]
    fn nesting_too_deep_is_named_with_its_line() {
        let dotted = |depth: usize| vec!["a"; depth].join(".");
        let arrays = |depth: usize| format!("{}{}", "[".repeat(depth), "]".repeat(depth));
        let cases = [
            (format!("seed = 1\n[{}]\n", dotted(200)), 2),
            // The deepest the reader takes, a comment, then one more (the review: the line
            // before was named).
            (format!("seed = 1\n{} = 1\n# {}\n\n{} = 2\n", dotted(80), dotted(90), dotted(81).replace('a', "b")), 5),
            (format!("seed = 1\n\n{} = 1\n", dotted(100)), 3),
            (format!("seed = 1\na = {}\n", arrays(200)), 2),
        ];
        for (text, line) in &cases {
            let error = toml::from_str::<toml::Table>(text).unwrap_err();
            let described = describe(text, &error);
            assert!(
                described.message.starts_with("keys, tables or arrays nested more than 80"),
                "{}",
                described.message
            );
            assert_eq!(described.line_column.map(|(l, _)| l), Some(*line), "{}", described.message);
        }
        let shallow = format!("[{}]\n", dotted(TOML_NESTING_LIMIT - 1));
        assert!(toml::from_str::<toml::Table>(&shallow).is_ok());
    }

    /// A byte-order mark is not a column: `seed` after one was reported a column late.
    #[test]
    fn a_byte_order_mark_is_not_a_column() {
        let text = "\u{feff}seed = \"x\"\nrows = 1\n";
        assert_eq!(line_column(text, text.find('"').unwrap()), (1, 8));
        assert_eq!(line_column(text, text.find("rows").unwrap()), (2, 1));
        assert_eq!(line_column("seed = \"x\"", 7), (1, 8), "negative control: the same without the mark");
    }

    /// serde's parts only, whole names only: the value a message quotes is left as written.
    #[test]
    fn type_names_are_replaced_whole() {
        let cases = [
            ("invalid type: string \"x\", expected u64", "invalid type: string \"x\", expected a whole number"),
            (
                "invalid type: floating point `4.0`, expected u32",
                "invalid type: floating point `4.0`, expected a whole number",
            ),
            (
                "invalid type: integer `99999999999999999999` as i128, expected u64",
                "invalid value: integer `99999999999999999999`, expected a whole number from 0 to 18446744073709551615",
            ),
            (
                "invalid type: integer `99999999999999999999` as i128, expected a string",
                "invalid type: integer `99999999999999999999` as i128, expected a string",
            ),
            (
                "invalid value: integer `5000000000`, expected u32",
                "invalid value: integer `5000000000`, expected a whole number from 0 to 4294967295",
            ),
            (
                "invalid value: integer `-1`, expected u32",
                "invalid value: integer `-1`, expected a whole number from 0 to 4294967295",
            ),
            (
                "invalid type: string \"expected f64\", expected f64",
                "invalid type: string \"expected f64\", expected a number",
            ),
            ("invalid type: sequence, expected a string", "invalid type: array, expected a string"),
            ("invalid type: integer `5`, expected struct Scales", "invalid type: integer `5`, expected a table"),
            ("invalid type: string \"x\", expected u320", "invalid type: string \"x\", expected u320"),
            // A float in exponent form beyond the plain range; within it, as serde wrote it.
            (
                &format!("invalid type: floating point `1{}.0`, expected u32", "0".repeat(300)),
                "invalid type: floating point `1e300`, expected a whole number",
            ),
            (
                "invalid type: floating point `23.0`, expected u32",
                "invalid type: floating point `23.0`, expected a whole number",
            ),
            (
                "invalid type: floating point `0.00001`, expected u8",
                "invalid type: floating point `1e-5`, expected a whole number",
            ),
        ];
        for (serde, plain) in cases {
            assert_eq!(plain_type_names(serde), plain);
        }
    }

    /// Keys in tables, in arrays of tables, and a single table read as item 0. Negative
    /// control: a key that is not written has no line.
    #[test]
    fn a_dotted_key_has_the_line_it_is_written_on() {
        let key_line = |text: &str, dotted: &str| KeyLines::new(text).line(dotted);
        let jobs = "# jobs\n[[job]]\npreset = \"a\"\n\n[[job]]\npreset = \"b\"\nset = { \"scales.rows\" = 3 }\n";
        assert_eq!(key_line(jobs, "job.0.preset"), Some(3));
        assert_eq!(key_line(jobs, "job.1.preset"), Some(6));
        assert_eq!(key_line(jobs, "job.1.set"), Some(7));
        assert_eq!(key_line(jobs, "job.0.set"), None);
        let preset = "seed = 1\n[pattern]\nkind = \"spots\"\nsize = 9.0";
        assert_eq!(key_line(preset, "pattern.0.size"), Some(4));
        assert_eq!(key_line(preset, "seed"), Some(1));
        // A `set` written as a sub-table (its key is on the header line), as dotted keys, and
        // jobs as an inline array.
        let sub_table = "[[job]]\npreset = \"a\"\n[job.set]\n\"scales.rows\" = 3\n";
        assert_eq!(key_line(sub_table, "job.0.set"), Some(3));
        let dotted = "[[job]]\npreset = \"a\"\nset.seed = 3\n";
        assert_eq!(key_line(dotted, "job.0.set"), Some(3));
        let inline = "job = [\n  { preset = \"a\" },\n  { preset = \"b\", set = { seed = 1 } },\n]\n";
        assert_eq!(key_line(inline, "job.1.set"), Some(3));
        assert_eq!(key_line(inline, "job.2.preset"), None);
    }
}
