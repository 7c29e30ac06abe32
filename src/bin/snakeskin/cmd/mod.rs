//! One file per command: each turns its typed arguments into library calls and prints the
//! result. Nothing here computes anything the library could not do without it.

mod batch;
mod bench;
mod brdf;
mod export;
mod figures;
mod gallery;
mod generate;
mod graph;
mod presets;
mod preview;
mod sheet;
mod verify;

use anyhow::Result;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> Result<()> {
    // Checked before any command runs, so a typo cannot switch the memory check off.
    snakeskin::memory::limit_from_env()?;
    snakeskin::memory::tile_budget_from_env()?;
    match cli.command {
        Command::Generate(args) => generate::run(args),
        Command::Export(args) => export::run(args),
        Command::Batch(args) => batch::run(args),
        Command::Graph(args) => graph::run(args),
        Command::Brdf { command } => brdf::run(command),
        Command::Bench { command } => bench::run(command),
        Command::Preview(args) => preview::run(args),
        Command::Figures { preset, out, size, map_size } => figures::run(&preset, &out, size, map_size),
        Command::Gallery { out, tile, columns, closeups } => {
            gallery::run(&out, tile as usize, columns as usize, closeups.as_deref())
        }
        Command::Sheet { out, tile, columns, map_size, layout, species, closeups } => {
            let options = snakeskin::render::figures::sheet::SheetOptions {
                tile,
                columns,
                map_size: map_size as usize,
                closeups,
            };
            sheet::run(&out, options, layout.layout(), &species)
        }
        Command::Presets { command } => presets::run(command),
        Command::Verify { paths } => verify::run(&paths),
    }
}
