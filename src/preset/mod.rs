//! Snake presets: the TOML schema, loading with helpful errors, validation, and the built-in
//! species library.

mod error;
pub mod library;
mod load;
pub mod schema;
pub mod validate;
pub mod visible;

pub use error::{LocatedProblem, Location, PresetError, SET_FLAG, describe_problems, place};
pub use load::{
    LoadedPreset, MAX_PRESET_BYTES, PresetSource, input_file, load, load_beside, names_a_file, parse, parse_seed_text,
    parse_with_seed, read_source, read_source_beside,
};
pub use schema::Preset;
