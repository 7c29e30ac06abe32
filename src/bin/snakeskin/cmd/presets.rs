//! `snakeskin presets list|show`: the built-in species library.

use anyhow::Result;

use crate::cli::PresetsCommand;
use snakeskin::preset::library;

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
            // Only built-in presets: "not a .toml file" was untrue for a file's path.
            None => {
                let names = library::names();
                let hint = library::suggest(&name).map(|n| format!("; did you mean {n}?")).unwrap_or_default();
                let file = if name.ends_with(".toml") { " (a preset file is its own TOML: open it)" } else { "" };
                let reason = format!("{name:?} is not a built-in preset{file}{hint} (built-in: {})", names.join(", "));
                Err(snakeskin::Error::InvalidOption { option: "preset name", reason }.into())
            }
        },
    }
}
