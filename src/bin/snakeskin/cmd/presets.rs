//! `snakeskin presets list|show`: the built-in species library.

use anyhow::Result;

use crate::cli::PresetsCommand;
use snakeskin::preset::{PresetError, library};

pub fn run(command: PresetsCommand) -> Result<()> {
    match command {
        PresetsCommand::List => {
            println!("{:<26} {:<26} {:<32} category", "name", "species", "common name");
            for (name, text) in library::all() {
                let preset: snakeskin::preset::Preset = toml::from_str(text)?;
                println!(
                    "{name:<26} {:<26} {:<32} {}",
                    preset.species.unwrap_or_default(),
                    preset.common_name.unwrap_or_default(),
                    preset.category.map(|c| c.name()).unwrap_or("-")
                );
            }
            Ok(())
        }
        PresetsCommand::Show { name } => match library::get(&name) {
            Some(text) => {
                print!("{text}");
                Ok(())
            }
            None => Err(snakeskin::Error::Preset(PresetError::UnknownPreset {
                available: library::names().join(", "),
                name,
            })
            .into()),
        },
    }
}
