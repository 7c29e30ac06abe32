//! Tables that take seconds to build and never change between runs, built once here and
//! shipped in the binary: the rough lobe's tables (`energy::tables`, material-free) and the
//! path table of the material every built-in species and `brdf`'s defaults use
//! (`path::PathTable` for n0 = 1, n2 = 2, the thesis' indices).
//!
//! Why: both are deterministic (fixed seeds, the same on any thread count) but walked photon
//! by photon, and every command that reads the layered model built them first: 1.2 s for the
//! lobe tables and 1.4 s for the path table on this machine's two cores, so a 64 × 64
//! `preview` took 4.7–5.3 s and `brdf eval` 2.8 s. Another material's path table is still
//! built on first use (`path::cached`).
//!
//! The files are the tables' numbers, little-endian, in the tables' own order (no header:
//! a file whose length is not the table's is not used, and the table is built). The test
//! `the_baked_tables_are_the_ones_the_code_builds` builds both and compares; after a change to
//! how they are built it fails, and `SNAKESKIN_BLESS_TABLES=1 cargo test --lib baked` writes
//! them anew.

use super::energy::{E1_MU, E1_ROUGHNESS, NODE_LEN};
use super::path::{PathTable, THROUGH_LEN};

/// The rough lobe's nodes (`energy::Tables::nodes`): `NODE_LEN` f32 per node.
const LOBE_TABLES: &[u8] = include_bytes!("baked/lobe_tables.bin");
/// The path table of (n0, n2) = `PATH_INDICES`: `delta` (one f64 per entry), then `through`
/// (`THROUGH_LEN` f64 per entry).
const PATH_TABLE: &[u8] = include_bytes!("baked/path_table_1_2.bin");
/// The indices of the baked path table, as its file name says: `material::thesis`'s ambient
/// and pigment indices, the defaults of a preset's optics and of `brdf`.
pub const PATH_INDICES: (f64, f64) = (1.0, 2.0);
const _: () = assert!(
    PATH_INDICES.0 == crate::material::thesis::AMBIENT_IOR && PATH_INDICES.1 == crate::material::thesis::PIGMENT_IOR,
    "the baked path table is the thesis indices'; bake the new ones (see the module)"
);

const ENTRIES: usize = E1_MU * E1_ROUGHNESS;

/// The baked lobe nodes, or None where the file does not fit the table's shape.
pub fn lobe_nodes() -> Option<Vec<[f32; NODE_LEN]>> {
    (LOBE_TABLES.len() == ENTRIES * NODE_LEN * 4).then(|| {
        LOBE_TABLES
            .chunks_exact(NODE_LEN * 4)
            .map(|node| {
                std::array::from_fn(|k| f32::from_le_bytes(node[4 * k..4 * k + 4].try_into().expect("4 bytes")))
            })
            .collect()
    })
}

/// The baked path table for (n0, n2), where these are `PATH_INDICES` and the file fits.
pub fn path_table(n0: f64, n2: f64) -> Option<PathTable> {
    if (n0, n2) != PATH_INDICES || PATH_TABLE.len() != ENTRIES * (1 + THROUGH_LEN) * 8 {
        return None;
    }
    let values: Vec<f64> =
        PATH_TABLE.chunks_exact(8).map(|v| f64::from_le_bytes(v.try_into().expect("8 bytes"))).collect();
    let (delta, through) = values.split_at(ENTRIES);
    let through: Vec<[f64; THROUGH_LEN]> =
        through.chunks_exact(THROUGH_LEN).map(|t| t.try_into().expect("an entry")).collect();
    Some(PathTable::from_parts(n0, n2, delta.to_vec(), through))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The files' bytes (`lobe_nodes` and `path_table` read them back).
    fn lobe_bytes(nodes: &[[f32; NODE_LEN]]) -> Vec<u8> {
        nodes.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn path_bytes(table: &PathTable) -> Vec<u8> {
        table.delta.iter().chain(table.through.iter().flatten()).flat_map(|v| v.to_le_bytes()).collect()
    }

    /// The baked tables are what the code builds now: bit for bit on x86-64 Linux with glibc,
    /// where they were baked (a change that moves a value by less than a walk's noise must
    /// bake them again too). On another platform a libm that rounds its last bit differently
    /// may send a photon another way, which moves a walked slot by about one photon's share,
    /// so slots may differ by 2e-3 there (a table built with a changed constant or rule moves
    /// by far more: with MULTIPLE_PHOTONS 32768 → 16384, 0.85; with the path walk's PHOTONS
    /// 4096 → 2048, 0.02; both seen). Failing, it says how to bake them again.
    #[test]
    fn the_baked_tables_are_the_ones_the_code_builds() {
        let built_lobes = super::super::energy::build_lobe_nodes();
        let (n0, n2) = PATH_INDICES;
        let built_path = PathTable::walked(n0, n2);
        if std::env::var_os("SNAKESKIN_BLESS_TABLES").is_some() {
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/optics/brdf/baked");
            std::fs::write(dir.join("lobe_tables.bin"), lobe_bytes(&built_lobes)).unwrap();
            std::fs::write(dir.join("path_table_1_2.bin"), path_bytes(&built_path)).unwrap();
            return;
        }
        let again = "bake them again: SNAKESKIN_BLESS_TABLES=1 cargo test --lib baked";
        let baked_lobes = lobe_nodes().unwrap_or_else(|| panic!("the lobe tables' file has the wrong length; {again}"));
        let baked_path =
            path_table(n0, n2).unwrap_or_else(|| panic!("the path table's file has the wrong length; {again}"));
        let pairs = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let lobe = |nodes: &[[f32; NODE_LEN]]| nodes.iter().flatten().map(|v| f64::from(*v)).collect::<Vec<_>>();
        let through = |t: &PathTable| t.through.iter().flatten().copied().collect::<Vec<_>>();
        let worst = [
            ("lobe tables", pairs(&lobe(&baked_lobes), &lobe(&built_lobes))),
            ("path deltas", pairs(&baked_path.delta, &built_path.delta)),
            ("straight-back rules", pairs(&through(&baked_path), &through(&built_path))),
        ];
        let exact = lobe_bytes(&baked_lobes) == lobe_bytes(&built_lobes) && baked_path == built_path;
        eprintln!("baked tables: exactly the built ones: {exact}; largest differences {worst:?}");
        let baking_platform = cfg!(all(target_arch = "x86_64", target_os = "linux", target_env = "gnu"));
        assert!(exact || !baking_platform, "the baked tables are not the built ones ({worst:?}); {again}");
        for (what, difference) in worst {
            assert!(difference <= 2e-3, "the baked {what} differ from the built by {difference}; {again}");
        }
    }

    /// The tables the model reads are the baked ones, and another material's path table is
    /// walked (negative control: the baked one is not handed out for other indices).
    #[test]
    fn the_model_reads_the_baked_tables() {
        assert_eq!(super::super::energy::tables().nodes, lobe_nodes().unwrap());
        let (n0, n2) = PATH_INDICES;
        assert_eq!(*super::super::path::cached(n0, n2), path_table(n0, n2).unwrap());
        assert!(path_table(n0, 1.5).is_none() && path_table(1.33, n2).is_none());
    }
}
