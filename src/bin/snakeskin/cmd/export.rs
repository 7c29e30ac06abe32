//! `snakeskin export --gltf FILE`: a preset on a mesh as glTF 2.0, with a progress bar.

use anyhow::Result;

use crate::cli::ExportArgs;
use crate::output::path_line;
use crate::progress::Progress;
use snakeskin::gltf_export::{ExportPlan, ExportRequest};

pub fn run(args: ExportArgs) -> Result<()> {
    let request = ExportRequest {
        preset: args.source.preset.clone(),
        overrides: args.source.overrides.clone(),
        seed: args.source.seed,
        size: args.size,
        layout: args.layout.layout(),
        mesh: args.mesh.kind(),
        out: args.gltf.clone(),
        ao: args.ao,
    };
    // Checked and said before the work, as `generate` does: the preset's warnings, the
    // textures' size for glTF viewers, and a memory estimate close to what is available.
    let plan = ExportPlan::new(&request)?;
    for warning in plan.warnings() {
        eprintln!("{warning}");
    }
    crate::output::report_tight_memory(&plan.memory(), "this export");
    let bar = Progress::counting("{spinner} exporting [{bar:30}] {pos}/{len} nodes {elapsed}");
    let report = plan.run(&|done, total| bar.update(done, total))?;
    bar.finish();
    if report.created_folder
        && let Some(folder) = args.gltf.parent()
    {
        eprintln!("note: created folder {}", path_line(folder));
    }
    for file in &report.removed {
        eprintln!("note: removed {}, which this export does not reference (an earlier one's)", path_line(file));
    }
    for kept in &report.kept {
        eprintln!("warning: {}", crate::output::kept_words(kept));
    }
    for file in &report.files {
        println!("{}", path_line(file));
    }
    Ok(())
}
