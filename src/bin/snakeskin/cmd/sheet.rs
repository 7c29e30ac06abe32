//! `snakeskin sheet`: the species library's contact sheet.

use std::path::Path;

use anyhow::Result;

use crate::output::{ensure_parent_folder, path_line};
use crate::progress::Progress;
use snakeskin::render::Renderer;
use snakeskin::render::figures::sheet::{SheetOptions, plan_sheet, write_sheet};

pub fn run(out: &Path, options: SheetOptions, layout: snakeskin::maps::Layout, species: &[String]) -> Result<()> {
    // Options, species and memory first: a wrong name is not a GPU's error.
    let plan = plan_sheet(options, layout, species)?;
    snakeskin::export::check_png_target(out)?;
    // The GPU before the folder: a run without an adapter said "created folder" of one it
    // then removed (a hostile-input review).
    let renderer = Renderer::headless()?;
    ensure_parent_folder(out)?;
    let bar = Progress::counting("{spinner} sheet [{bar:30}] {pos}/{len} species {elapsed}");
    let written = write_sheet(&renderer, out, &plan, &|done, total| bar.update(done, total))?;
    bar.finish();
    println!("{}", path_line(&written));
    Ok(())
}
