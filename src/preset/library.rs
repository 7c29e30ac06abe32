//! The built-in species presets, embedded in the binary from `presets/*.toml`.

/// (name, TOML text), sorted by name. `tests/presets.rs` checks that every file in
/// `presets/` is listed here.
const PRESETS: &[(&str, &str)] = &[
    ("bitis-gabonica", include_str!("../../presets/bitis-gabonica.toml")),
    ("boa-constrictor", include_str!("../../presets/boa-constrictor.toml")),
    ("bothrops-alternatus", include_str!("../../presets/bothrops-alternatus.toml")),
    ("crotalus-atrox", include_str!("../../presets/crotalus-atrox.toml")),
    ("dendroaspis-polylepis", include_str!("../../presets/dendroaspis-polylepis.toml")),
    ("epicrates-cenchria", include_str!("../../presets/epicrates-cenchria.toml")),
    ("erythrolamprus-miliaris", include_str!("../../presets/erythrolamprus-miliaris.toml")),
    ("lampropeltis-triangulum", include_str!("../../presets/lampropeltis-triangulum.toml")),
    ("leiopython-albertisii", include_str!("../../presets/leiopython-albertisii.toml")),
    ("micrurus-diastema", include_str!("../../presets/micrurus-diastema.toml")),
    ("morelia-viridis", include_str!("../../presets/morelia-viridis.toml")),
    ("pantherophis-guttatus", include_str!("../../presets/pantherophis-guttatus.toml")),
    ("phalotris-lemniscatus", include_str!("../../presets/phalotris-lemniscatus.toml")),
    ("philodryas-aestiva", include_str!("../../presets/philodryas-aestiva.toml")),
    ("philodryas-olfersii", include_str!("../../presets/philodryas-olfersii.toml")),
    ("ptychophis-flavovirgatus", include_str!("../../presets/ptychophis-flavovirgatus.toml")),
    ("python-regius", include_str!("../../presets/python-regius.toml")),
    ("thamnophis-sirtalis", include_str!("../../presets/thamnophis-sirtalis.toml")),
    ("vipera-berus", include_str!("../../presets/vipera-berus.toml")),
    ("xenopeltis-unicolor", include_str!("../../presets/xenopeltis-unicolor.toml")),
];

pub fn names() -> Vec<&'static str> {
    PRESETS.iter().map(|(n, _)| *n).collect()
}

pub fn get(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
}

pub fn all() -> &'static [(&'static str, &'static str)] {
    PRESETS
}
