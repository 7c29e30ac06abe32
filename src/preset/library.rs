//! The built-in species presets, embedded in the binary from `presets/*.toml`.

/// (name, TOML text), sorted by name. `tests/presets.rs` checks that every file in
/// `presets/` is listed here.
const PRESETS: &[(&str, &str)] = &[
    ("acanthophis-antarcticus", include_str!("../../presets/acanthophis-antarcticus.toml")),
    ("acrochordus-granulatus", include_str!("../../presets/acrochordus-granulatus.toml")),
    ("ahaetulla-nasuta", include_str!("../../presets/ahaetulla-nasuta.toml")),
    ("bitis-arietans", include_str!("../../presets/bitis-arietans.toml")),
    ("bitis-gabonica", include_str!("../../presets/bitis-gabonica.toml")),
    ("boa-constrictor", include_str!("../../presets/boa-constrictor.toml")),
    ("bothrops-alternatus", include_str!("../../presets/bothrops-alternatus.toml")),
    ("bungarus-fasciatus", include_str!("../../presets/bungarus-fasciatus.toml")),
    ("corallus-caninus", include_str!("../../presets/corallus-caninus.toml")),
    ("crotalus-atrox", include_str!("../../presets/crotalus-atrox.toml")),
    ("dendroaspis-polylepis", include_str!("../../presets/dendroaspis-polylepis.toml")),
    ("diadophis-punctatus", include_str!("../../presets/diadophis-punctatus.toml")),
    ("elaphe-climacophora", include_str!("../../presets/elaphe-climacophora.toml")),
    ("epicrates-cenchria", include_str!("../../presets/epicrates-cenchria.toml")),
    ("erythrolamprus-miliaris", include_str!("../../presets/erythrolamprus-miliaris.toml")),
    ("hydrophis-platurus", include_str!("../../presets/hydrophis-platurus.toml")),
    ("lampropeltis-triangulum", include_str!("../../presets/lampropeltis-triangulum.toml")),
    ("leiopython-albertisii", include_str!("../../presets/leiopython-albertisii.toml")),
    ("liasis-mackloti", include_str!("../../presets/liasis-mackloti.toml")),
    ("loxocemus-bicolor", include_str!("../../presets/loxocemus-bicolor.toml")),
    ("micrurus-diastema", include_str!("../../presets/micrurus-diastema.toml")),
    ("morelia-spilota", include_str!("../../presets/morelia-spilota.toml")),
    ("morelia-viridis", include_str!("../../presets/morelia-viridis.toml")),
    ("natrix-natrix", include_str!("../../presets/natrix-natrix.toml")),
    ("pantherophis-guttatus", include_str!("../../presets/pantherophis-guttatus.toml")),
    ("phalotris-lemniscatus", include_str!("../../presets/phalotris-lemniscatus.toml")),
    ("philodryas-aestiva", include_str!("../../presets/philodryas-aestiva.toml")),
    ("philodryas-olfersii", include_str!("../../presets/philodryas-olfersii.toml")),
    ("pseudechis-porphyriacus", include_str!("../../presets/pseudechis-porphyriacus.toml")),
    ("ptychophis-flavovirgatus", include_str!("../../presets/ptychophis-flavovirgatus.toml")),
    ("python-regius", include_str!("../../presets/python-regius.toml")),
    ("thamnophis-sirtalis", include_str!("../../presets/thamnophis-sirtalis.toml")),
    ("vipera-berus", include_str!("../../presets/vipera-berus.toml")),
    ("xenopeltis-unicolor", include_str!("../../presets/xenopeltis-unicolor.toml")),
];

pub fn names() -> Vec<&'static str> {
    PRESETS.iter().map(|(n, _)| *n).collect()
}

/// The built-in name a mistyped one most likely means, for "did you mean": the same name in
/// another case or with `_` or spaces for `-` (`Natrix_natrix`), a file's stem
/// (`presets/natrix-natrix.toml`), a species' common name written so (`grass-snake`, `"Corn
/// snake"`, `macklots-python`: an artist's first guess, which had no suggestion), the one
/// species of a genus (`natrix`), or the nearest by edits. `natrix_natrix` and `natrix` had
/// no suggestion.
pub fn suggest(name: &str) -> Option<&'static str> {
    let stem = std::path::Path::new(name).file_stem().map_or(name.into(), |s| s.to_string_lossy());
    let normal = normal_name(&stem);
    if let Some(same) = names().into_iter().find(|n| *n == normal) {
        return Some(same);
    }
    let common = |text: &str| {
        let table = toml::from_str::<toml::Table>(text).ok()?;
        table.get("common_name")?.as_str().map(normal_name)
    };
    if let Some((name, _)) = PRESETS.iter().find(|(_, text)| common(text).is_some_and(|c| c == normal)) {
        return Some(name);
    }
    let genus: Vec<&str> = names().into_iter().filter(|n| n.starts_with(&format!("{normal}-"))).collect();
    if let [only] = genus[..] {
        return Some(only);
    }
    crate::toml_text::nearest(&normal, names())
}

/// A name as the suggestions compare it: trimmed, lower case, `_` and spaces as `-`,
/// apostrophes dropped (`Macklot's python` is `macklots-python`).
fn normal_name(name: &str) -> String {
    name.trim().to_lowercase().replace(['_', ' '], "-").replace(['\'', '’'], "")
}

pub fn get(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, text)| *text)
}

pub fn all() -> &'static [(&'static str, &'static str)] {
    PRESETS
}
