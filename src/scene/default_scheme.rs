//! Which scheme an Xpbd-model scene runs when its file names none (issue 31): the
//! implicit scheme, `Newton(())`, which reaches XPBD's converged tear at a fraction of the
//! substeps (docs/physics-notes.md, "Which scheme a scene runs"). A scene that writes
//! `solver.scheme` keeps it; one that asks for the seed's constraint pair or eq. 3 stress,
//! which only XPBD has, must say `scheme: Xpbd`.

use std::path::Path;

use incise_sim::implicit::{NewtonParams, Scheme};
use incise_sim::stress::StressMeasure;
use incise_sim::xpbd::ConstraintPair;
use serde::Deserialize;
use serde::de::{Deserializer, IgnoredAny};

use super::{Method, Scene, SceneError, locate};

/// The scheme of a scene whose file names none: `Newton(())`, the implicit scheme at
/// its defaults.
pub fn default_scheme() -> Scheme {
    Scheme::Newton(NewtonParams::default())
}

/// Give an Xpbd-model scene whose text leaves out `solver.scheme` the default scheme;
/// refuse one that also asks for what only XPBD has, at that field's line.
pub(super) fn apply(scene: &mut Scene, text: &str, path: &Path) -> Result<(), SceneError> {
    if scene.model.method() != Method::Xpbd || names_a_scheme(text, path)? {
        return Ok(());
    }
    let seed_only = if scene.solver.constraints != ConstraintPair::RestFree {
        Some(("solver.constraints", "the seed's γ-shifted constraint pair"))
    } else if scene.solver.stress != StressMeasure::Cauchy {
        Some(("solver.stress", "the seed's eq. 3 stress"))
    } else {
        None
    };
    if let Some((field, what)) = seed_only {
        return Err(SceneError::Value {
            path: path.into(),
            line: locate(text, field),
            field: field.into(),
            msg: format!(
                "asks for {what}, which only the XPBD scheme has; a scene that names no \
                 scheme runs the implicit one (Newton): add `scheme: Xpbd` to solver"
            ),
        });
    }
    scene.solver.scheme = default_scheme();
    Ok(())
}

/// Whether the scene text writes `solver.scheme` (the text parsed again into a struct
/// that sees only that field).
fn names_a_scheme(text: &str, path: &Path) -> Result<bool, SceneError> {
    let probe: SceneProbe = incise_sim::ron_file::parse(text, path)?;
    Ok(probe.solver.scheme.0)
}

/// A scene seen only for its `solver`.
#[derive(Default, Deserialize)]
struct SceneProbe {
    #[serde(default)]
    solver: SolverProbe,
}

/// A `solver` seen only for its `scheme`.
#[derive(Default, Deserialize)]
struct SolverProbe {
    #[serde(default)]
    scheme: Written,
}

/// Whether a field was written, whatever its value.
#[derive(Default)]
struct Written(bool);

impl<'de> Deserialize<'de> for Written {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        IgnoredAny::deserialize(d).map(|_| Written(true))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse_scene;

    const BARE: &str = r#"(
        name: "t",
        mesh: Generate(Block(min: (0, 0, 0), size: (0.1, 0.02, 0.02), cells: (5, 1, 1))),
        material: Custom((youngs_modulus: 1e4, poisson_ratio: 0.3, density: 1000)),
        pins: [PlaneSide(point: (0, 0, 0), normal: (-1, 0, 0))],
        solver: (substeps: 12, damping: 2.0),
        cutting: Some((von_mises_threshold: 4e3)),
        tool: Some((file: "tools/scalpel_10.ron")),
        duration: 1.0,
    )"#;

    fn parse(text: &str) -> Result<Scene, String> {
        parse_scene(text, Path::new("t.ron")).map_err(|e| e.to_string())
    }

    /// A scene that names no scheme runs the implicit one; one that names XPBD keeps it;
    /// one that names Newton keeps its own settings.
    #[test]
    fn a_scene_naming_no_scheme_runs_the_implicit_one() {
        assert_eq!(parse(BARE).unwrap().solver.scheme, default_scheme());
        let no_solver = BARE.replace("solver: (substeps: 12, damping: 2.0),", "");
        assert_eq!(parse(&no_solver).unwrap().solver.scheme, default_scheme());
        let xpbd = BARE.replace("substeps: 12,", "scheme: Xpbd, substeps: 12,");
        assert_eq!(parse(&xpbd).unwrap().solver.scheme, Scheme::Xpbd);
        let own = BARE.replace("substeps: 12,", "scheme: Newton((steps: 2)), substeps: 12,");
        let Scheme::Newton(p) = parse(&own).unwrap().solver.scheme else {
            panic!("not Newton")
        };
        assert_eq!(p.steps, 2);
    }

    /// The seed's pair or stress without a scheme is refused at its line, with the fix.
    #[test]
    fn the_seeds_pair_without_a_scheme_is_refused_at_its_line() {
        let seed = BARE.replace(
            "damping: 2.0),",
            "damping: 2.0,\n constraints: GammaShifted),",
        );
        let e = parse(&seed).unwrap_err();
        assert!(e.starts_with("t.ron:7: solver.constraints"), "{e}");
        assert!(e.contains("scheme: Xpbd"), "{e}");
        let eq3 = BARE.replace("damping: 2.0),", "damping: 2.0,\n stress: PaperEq3),");
        assert!(
            parse(&eq3)
                .unwrap_err()
                .starts_with("t.ron:7: solver.stress")
        );
        let named = seed.replace("substeps: 12,", "scheme: Xpbd, substeps: 12,");
        assert_eq!(parse(&named).unwrap().solver.scheme, Scheme::Xpbd);
    }

    /// The shipped scenes run the schemes docs/physics-notes.md ("Which scheme a scene
    /// runs") gives them: by default or by name.
    #[test]
    fn the_shipped_scenes_run_the_schemes_the_notes_give() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        let scheme = |name: &str| {
            let s = crate::scene::load_scene(&root.join(name)).unwrap();
            s.solver.scheme.name()
        };
        for name in [
            "plate_cut.ron",
            "intestine_incision.ron",
            "beam_sag.ron",
            "intestine_pull.ron",
            "bowel_cantilever.ron",
        ] {
            assert_eq!(scheme(name), "Newton", "{name}");
        }
        for name in [
            "slab_layer.ron",
            "intestine_enterotomy.ron",
            "plate_stretch.ron",
            "intestine_pull_xpbd.ron",
        ] {
            assert_eq!(scheme(name), "XPBD", "{name}");
        }
    }

    /// Other methods have no tet scheme to default.
    #[test]
    fn a_mass_spring_scene_gets_no_scheme() {
        let nakao = BARE.replace("duration: 1.0,", "duration: 1.0, model: MassSpring(()),");
        assert_eq!(parse(&nakao).unwrap().solver.scheme, Scheme::Xpbd);
    }
}
