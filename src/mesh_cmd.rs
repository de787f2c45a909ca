//! `incise mesh check` and `incise mesh gen`.

use std::path::Path;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use incise_sim::mesh::quality::assess;
use incise_sim::skin::Skin;
use incise_sim::{TetMesh, generate, io};

/// Procedural meshes available from the CLI.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum GenKind {
    /// Nakao 2003 plate, 16 × 16 × 0.4 cm.
    Plate,
    /// ≈34k-tet curved intestine with a finer skin.
    Intestine,
    /// 10 × 2 × 2 cm block, 10 × 2 × 2 cells.
    Block,
    /// 20 cm × 2 cm × 2 cm beam, 40 × 4 × 4 cells.
    Beam,
}

/// Load `file`, print counts and quality; an unreadable mesh or one with degenerate tets
/// is an error (exit 1) naming the file and line or the tet.
pub fn check(file: &Path, json: bool) -> Result<()> {
    let raw = io::load_mesh(file)?;
    let warnings = raw.warnings.clone();
    let q = assess(&raw);
    if json {
        println!("{}", serde_json::to_string_pretty(&q)?);
    } else {
        println!("{}", file.display());
        println!("  nodes            {}", q.nodes);
        println!("  tets             {}", q.tets);
        if let Some(b) = q.boundary_faces {
            println!("  boundary faces   {b}");
        }
        if let Some(c) = q.components {
            println!("  components       {c}");
        }
        println!(
            "  volume           min {:.4e}  max {:.4e}  total {:.4e}",
            q.volume_min, q.volume_max, q.volume_total
        );
        println!(
            "  dihedral angle   min {:.2}°  max {:.2}°",
            q.dihedral_min_deg, q.dihedral_max_deg
        );
        println!(
            "  inverted tets    {} (re-oriented on load)",
            q.inverted_tets
        );
        println!("  degenerate tets  {}", q.degenerate_tets);
        println!("  unused nodes     {}", q.unused_nodes);
        for w in &warnings {
            println!("  warning: {w}");
        }
    }
    if let Some(t) = q.first_degenerate {
        bail!(
            "{}: {} degenerate tets (first: tet {t}); the solver cannot use this mesh",
            file.display(),
            q.degenerate_tets
        );
    }
    TetMesh::from_raw(raw).with_context(|| file.display().to_string())?;
    Ok(())
}

/// Write a procedural mesh as `out.node`/`out.ele` plus its skin as `out.obj`.
pub fn generate(kind: GenKind, out: &Path) -> Result<()> {
    let (raw, skin) = match kind {
        GenKind::Plate => (generate::plate(), None),
        GenKind::Intestine => {
            let (raw, skin) = generate::intestine(&generate::IntestineParams::default());
            (raw, Some(skin))
        }
        GenKind::Block => (
            generate::block(
                glam::Vec3::ZERO,
                glam::Vec3::new(0.1, 0.02, 0.02),
                glam::UVec3::new(10, 2, 2),
            ),
            None,
        ),
        GenKind::Beam => (
            generate::beam(0.2, 0.02, 0.02, glam::UVec3::new(40, 4, 4)),
            None,
        ),
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    io::write_tetgen(out, &raw.positions, &raw.tets)?;
    let (mesh, _) = TetMesh::from_raw(raw)?;
    let skin = match skin {
        Some(s) => s,
        None => Skin::from_boundary(&mesh).surface,
    };
    let obj = out.with_extension("obj");
    io::write_obj(&obj, &skin)?;
    println!(
        "{}.node/.ele: {} nodes, {} tets; {}: {} skin triangles",
        out.display(),
        mesh.node_count(),
        mesh.tet_count(),
        obj.display(),
        skin.triangles.len()
    );
    Ok(())
}
