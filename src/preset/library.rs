//! The built-in species presets, embedded in the binary from `presets/*.toml`.

/// (name, TOML text), sorted by name.
const PRESETS: &[(&str, &str)] =
    &[("erythrolamprus-miliaris", include_str!("../../presets/erythrolamprus-miliaris.toml"))];

pub fn names() -> Vec<&'static str> {
    PRESETS.iter().map(|(n, _)| *n).collect()
}

pub fn get(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
}

pub fn all() -> &'static [(&'static str, &'static str)] {
    PRESETS
}
