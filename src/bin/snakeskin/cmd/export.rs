//! `snakeskin export --gltf FILE`: a preset on a mesh as glTF 2.0, with a progress bar.

use anyhow::Result;

use crate::cli::ExportArgs;
use crate::output::path_line;
use crate::progress::Progress;
use snakeskin::gltf_export::{ExportRequest, export};

/// The largest texture side WebGL implementations commonly accept (MAX_TEXTURE_SIZE on
/// desktop GPUs; many mobile GPUs stop at 4096 or 8192).
const WEBGL_TEXTURE_LIMIT: usize = 16384;

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
    let bar = Progress::counting("{spinner} exporting [{bar:30}] {pos}/{len} nodes {elapsed}");
    let report = export(&request, &|done, total| bar.update(done, total))?;
    bar.finish();
    for warning in &report.warnings {
        eprintln!("{warning}");
    }
    if report.created_folder
        && let Some(folder) = args.gltf.parent()
    {
        eprintln!("note: created folder {}", path_line(folder));
    }
    let (width, height) = report.dimensions;
    if width.max(height) > WEBGL_TEXTURE_LIMIT {
        eprintln!(
            "warning: the textures are {width} x {height}; browsers' WebGL commonly loads at most {WEBGL_TEXTURE_LIMIT} \
             texels a side (a body atlas is body.length widths tall: use a smaller --size for web viewers)"
        );
    }
    for file in &report.files {
        println!("{}", path_line(file));
    }
    Ok(())
}
