//! End-to-end tests of rheology scenes with a material per region (issue 9): the shipped
//! layered organ runs through `incise run`, its residual dent lies between those of its
//! two materials alone, and bad region fields are named with file, line and field.

mod common;

use std::path::{Path, PathBuf};

use common::{incise, temp_dir, text};

const SCENE: &str = "config/organ_layers.ron";

/// The shipped scene's text with `edit` applied, written beside a copy of the presets.
fn variant(dir: &Path, name: &str, edit: impl Fn(String) -> String) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(SCENE)).unwrap();
    std::fs::copy(root.join("config/rheology.ron"), dir.join("rheology.ron")).unwrap();
    let path = dir.join(format!("{name}.ron"));
    std::fs::write(&path, edit(text)).unwrap();
    path
}

/// Run `scene` and return its report.
fn run(scene: &str, out: &Path) -> serde_json::Value {
    let o = incise(&[
        "run",
        scene,
        "--vtu-every",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("residual") && !stdout.contains("NaN"),
        "{stdout}"
    );
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(!json.contains("NaN"), "{json}");
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();
    for frame in report["frames"].as_array().unwrap() {
        for (key, value) in frame.as_object().unwrap() {
            assert!(value.is_number(), "frame field {key} is {value}");
        }
    }
    report
}

fn residual(report: &serde_json::Value) -> f64 {
    report["rheology"]["residual_dent_m"].as_f64().unwrap()
}

#[test]
fn layered_organ_dent_lies_between_its_materials_alone() {
    let dir = temp_dir("organ");
    let layered = run(SCENE, &dir.join("layered"));
    assert_eq!(layered["status"], "completed");
    assert_eq!(layered["model"], "rheology");
    let rows = layered["rheology"]["materials"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["preset"], "viscoelastic");
    assert_eq!(rows[1]["preset"], "rheological");
    let tets: u64 = rows.iter().map(|r| r["tets"].as_u64().unwrap()).sum();
    assert_eq!(tets, layered["mesh"]["tets"].as_u64().unwrap());
    // The 4 × 4 × 2 inner cells (6 tets each) are the core.
    assert_eq!(rows[1]["tets"], 192);
    // The indenter went 3 cm deep and the probe followed it.
    let max = layered["rheology"]["max_dent_m"].as_f64().unwrap();
    assert!((max - 0.03).abs() < 1e-3, "max dent {max}");
    let frames = layered["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 186, "3.1 s at 60 Hz");
    assert!(frames[0].get("max_von_mises").is_none());

    let all = |preset: &str| {
        let path = variant(&dir, preset, |t| {
            t.replace("\"viscoelastic\"", &format!("\"{preset}\""))
                .replace("\"rheological\"", &format!("\"{preset}\""))
        });
        residual(&run(path.to_str().unwrap(), &dir.join(preset)))
    };
    let (soft, clay, mixed) = (all("viscoelastic"), all("rheological"), residual(&layered));
    eprintln!(
        "residual dent: viscoelastic {:.3} mm, layered {:.3} mm, rheological {:.3} mm",
        soft * 1e3,
        mixed * 1e3,
        clay * 1e3
    );
    // PHYSICS.md §3: a Voigt body returns fully (issue 9 test 2: < 1 % of the dent) ...
    assert!(soft.abs() < 0.01 * max, "viscoelastic residual {soft}");
    // ... the rheological core keeps a dent of its own, and the elastic layer around it
    // pulls part of it back: clearly between the two.
    assert!(mixed > 0.1 * clay, "layered {mixed} vs rheological {clay}");
    assert!(mixed < 0.8 * clay, "layered {mixed} vs rheological {clay}");
}

/// Run a bad variant and return stderr, asserting it failed.
fn fails(name: &str, edit: impl Fn(String) -> String) -> String {
    let dir = temp_dir(name);
    let path = variant(&dir, name, edit);
    let o = incise(&[
        "run",
        path.to_str().unwrap(),
        "--quiet",
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "{name} should fail");
    text(&o.stderr)
}

#[test]
fn unknown_region_material_names_file_line_and_field() {
    let err = fails("unknown", |t| {
        t.replace("material: \"rheological\"", "material: \"rheologicl\"")
    });
    // The region's material is on line 29 of the shipped scene, the default on 24, the
    // region's tets on 28.
    assert!(
        err.contains("unknown.ron:29: model.regions[0].material"),
        "{err}"
    );
    assert!(
        err.contains("rheologicl") && err.contains("viscoelastic"),
        "{err}"
    );
    let err = fails("unknown_default", |t| {
        t.replace("material: \"viscoelastic\"", "material: \"jelly\"")
    });
    assert!(
        err.contains("unknown_default.ron:24: model.material"),
        "{err}"
    );
}

#[test]
fn empty_region_selections_name_the_field() {
    // A box beside the block selects no node.
    let err = fails("outside", |t| {
        t.replace(
            "Box(min: (-0.101, -0.101, -0.001), max: (0.101, 0.101, 0.101))",
            "Box(min: (1.0, 1.0, 1.0), max: (2.0, 2.0, 2.0))",
        )
    });
    assert!(
        err.contains("outside.ron:28: model.regions[0].tets"),
        "{err}"
    );
    assert!(err.contains("selects no node"), "{err}");
    // A box around one layer of nodes selects nodes but no whole tet.
    let err = fails("flat", |t| {
        t.replace(
            "Box(min: (-0.101, -0.101, -0.001), max: (0.101, 0.101, 0.101))",
            "Box(min: (-0.2, -0.2, 0.049), max: (0.2, 0.2, 0.051))",
        )
    });
    assert!(err.contains("flat.ron:28: model.regions[0].tets"), "{err}");
    assert!(err.contains("covers no tet"), "{err}");
    // An empty tet list.
    let err = fails("no_tets", |t| {
        t.replace(
            "Nodes(Box(min: (-0.101, -0.101, -0.001), max: (0.101, 0.101, 0.101)))",
            "Tets([])",
        )
    });
    assert!(
        err.contains("no_tets.ron:28: model.regions[0].tets"),
        "{err}"
    );
}

#[test]
fn material_field_is_refused_in_a_rheology_scene() {
    let err = fails("with_material", |t| {
        t.replace("    pins:", "    material: Preset(\"liver\"),\n    pins:")
    });
    assert!(
        err.contains("with_material.ron:") && err.contains("material is not used"),
        "{err}"
    );
}
