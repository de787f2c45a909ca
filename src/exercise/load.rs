//! Reading an exercise file: RON syntax and unknown fields with file:line:col, values out
//! of range and a plan off the organ with file:line and the field, as scene files do.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use incise_sim::TetMesh;
use incise_sim::ron_file;

use super::model::Exercise;
use super::plan::{Plan, RestSurface};
use crate::scene::{ModelChoice, Scene, SceneError, load_scene, locate, raw_mesh};

/// An exercise ready to score: the file, its scene and the plan on the organ's surface.
pub struct LoadedExercise {
    /// The exercise as written.
    pub exercise: Exercise,
    /// The exercise file.
    pub path: PathBuf,
    /// The scene file it names.
    pub scene_path: PathBuf,
    /// The scene.
    pub scene: Scene,
    /// The scene's tet mesh at rest.
    pub mesh: TetMesh,
    /// The plan projected onto the mesh's rest surface.
    pub plan: Plan,
}

/// Read, validate and place an exercise: its fields, its scene (an XPBD scene with a
/// scalpel, or a Nakao scene, whose blade a stroke file drives) and its plan (every point
/// within `surface_tolerance` of the organ's surface).
pub fn load_exercise(path: &Path) -> Result<LoadedExercise> {
    let (text, exercise, scene_path) = read_exercise(path)?;
    let value_err = |field: &str, line: usize, msg: String| SceneError::Value {
        path: path.into(),
        line,
        field: field.into(),
        msg,
    };
    let scene = load_scene(&scene_path).with_context(|| format!("{}: scene", path.display()))?;
    if let ModelChoice::Rheology(_) = scene.model {
        return Err(value_err(
            "scene",
            locate(&text, "scene"),
            format!(
                "{} is a Rheology scene, which does not cut: exercises are scored on what an \
                 XPBD body released or a MassSpring (Nakao) body cut open (docs/scoring.md); \
                 open it with `incise preview`, `incise xr` or `incise run`",
                scene_path.display()
            ),
        )
        .into());
    }
    if scene.tool.is_none() && matches!(scene.model, ModelChoice::Xpbd) {
        return Err(value_err(
            "scene",
            locate(&text, "scene"),
            format!(
                "{} has no tool: an exercise's scene needs `tool: Some((file: ...))`",
                scene_path.display()
            ),
        )
        .into());
    }
    let (raw, _) = raw_mesh(&scene.mesh, scene_path.parent().unwrap_or(Path::new(".")))
        .with_context(|| format!("{}: mesh", scene_path.display()))?;
    let (mesh, _) =
        TetMesh::from_raw(raw).with_context(|| format!("{}: mesh", scene_path.display()))?;
    let surface = RestSurface::of_mesh(&mesh);
    let plan =
        Plan::new(&exercise.plan, &surface, exercise.surface_tolerance as f64).map_err(|off| {
            value_err(
                &format!("plan[{}]", off.index),
                plan_point_line(&text, off.index),
                format!(
                    "is {:.1} mm from the surface of {}'s organ (allowed: surface_tolerance = \
                 {:.1} mm); plan points must lie on the tissue",
                    off.distance * 1e3,
                    scene_path.display(),
                    exercise.surface_tolerance * 1e3
                ),
            )
        })?;
    Ok(LoadedExercise {
        exercise,
        path: path.into(),
        scene_path,
        scene,
        mesh,
        plan,
    })
}

/// The scene file the exercise at `path` names, from its text alone (no mesh is built):
/// what a command needs to pick the session for the scene's method.
pub fn exercise_scene(path: &Path) -> Result<PathBuf> {
    Ok(read_exercise(path)?.2)
}

/// The exercise file's text, its checked fields and the scene file it names (which must
/// exist).
fn read_exercise(path: &Path) -> Result<(String, Exercise, PathBuf)> {
    let text = ron_file::read(path).map_err(SceneError::from)?;
    let exercise = parse_exercise(&text, path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let scene_path = dir.join(&exercise.scene);
    if !scene_path.is_file() {
        return Err(SceneError::Value {
            path: path.into(),
            line: locate(&text, "scene"),
            field: "scene".into(),
            msg: format!("names {}, which is not a file", scene_path.display()),
        }
        .into());
    }
    Ok((text, exercise, scene_path))
}

/// Parse exercise text and check every value's range; `path` names it in errors.
pub fn parse_exercise(text: &str, path: &Path) -> Result<Exercise, SceneError> {
    let ex: Exercise = ron_file::parse(text, path)?;
    let err = |field: &str, msg: String| SceneError::Value {
        path: path.into(),
        line: field_line(text, field),
        field: field.into(),
        msg,
    };
    if ex.name.trim().is_empty() {
        return Err(err("name", "must not be empty".into()));
    }
    if ex.plan.len() < 2 {
        return Err(err(
            "plan",
            format!(
                "has {} point(s): a planned incision needs at least 2",
                ex.plan.len()
            ),
        ));
    }
    for (i, p) in ex.plan.iter().enumerate() {
        if !p.is_finite() {
            return Err(SceneError::Value {
                path: path.into(),
                line: plan_point_line(text, i),
                field: format!("plan[{i}]"),
                msg: "must be finite".into(),
            });
        }
    }
    if ex.plan.windows(2).all(|w| w[0] == w[1]) {
        return Err(err(
            "plan",
            "has zero length: its points are all equal".into(),
        ));
    }
    let positive = |v: f32| v.is_finite() && v > 0.0;
    let checks: [(&str, f32, bool, &str); 10] = [
        ("depth", ex.depth, positive(ex.depth), "a depth > 0 m"),
        (
            "tolerance.lateral",
            ex.tolerance.lateral,
            positive(ex.tolerance.lateral),
            "a distance > 0 m",
        ),
        (
            "tolerance.depth",
            ex.tolerance.depth,
            positive(ex.tolerance.depth),
            "a distance > 0 m",
        ),
        (
            "surface_tolerance",
            ex.surface_tolerance,
            positive(ex.surface_tolerance),
            "a distance > 0 m",
        ),
        (
            "time_limit",
            ex.time_limit,
            positive(ex.time_limit),
            "a time > 0 s",
        ),
        (
            "pass.completion",
            ex.pass.completion,
            (0.0..=1.0).contains(&ex.pass.completion),
            "a fraction in 0..1",
        ),
        (
            "pass.mean_deviation",
            ex.pass.mean_deviation,
            positive(ex.pass.mean_deviation),
            "a distance > 0 m",
        ),
        (
            "pass.max_deviation",
            ex.pass.max_deviation,
            positive(ex.pass.max_deviation),
            "a distance > 0 m",
        ),
        (
            "pass.depth_error",
            ex.pass.depth_error,
            positive(ex.pass.depth_error),
            "a distance > 0 m",
        ),
        (
            "pass.max_force",
            ex.pass.max_force,
            positive(ex.pass.max_force),
            "a force > 0 N",
        ),
    ];
    for (field, value, ok, what) in checks {
        if !ok {
            return Err(err(field, format!("must be {what}, got {value}")));
        }
    }
    if !(ex.pass.collateral.is_finite() && ex.pass.collateral >= 0.0) {
        return Err(err(
            "pass.collateral",
            format!("must be a volume >= 0 m³, got {}", ex.pass.collateral),
        ));
    }
    if !(0.0..=100.0).contains(&ex.pass.score) {
        return Err(err(
            "pass.score",
            format!("must be in 0..100, got {}", ex.pass.score),
        ));
    }
    Ok(ex)
}

/// 1-based line of a dotted field (`tolerance.depth`: the first `depth:` from the line of
/// `tolerance:` on); 0 when absent.
fn field_line(text: &str, field: &str) -> usize {
    let Some((parent, last)) = field.rsplit_once('.') else {
        return locate(text, field);
    };
    match field_line(text, parent) {
        0 => locate(text, last),
        start => {
            let tail: String = text.lines().skip(start - 1).collect::<Vec<_>>().join("\n");
            match locate(&tail, last) {
                0 => start,
                l => start + l - 1,
            }
        }
    }
}

/// 1-based line of the `index`-th point of `plan: [...]` (the line of `plan:` when the
/// points cannot be told apart, 0 when there is no `plan:`).
fn plan_point_line(text: &str, index: usize) -> usize {
    let start = locate(text, "plan");
    if start == 0 {
        return 0;
    }
    let offset: usize = text.lines().take(start - 1).map(|l| l.len() + 1).sum();
    let tail = &text[offset..];
    let Some(open) = tail.find('[') else {
        return start;
    };
    let mut depth = 0usize;
    let mut seen = 0usize;
    for (i, c) in tail[open + 1..].char_indices() {
        match c {
            '(' if depth == 0 => {
                if seen == index {
                    let upto = offset + open + 1 + i;
                    return text[..upto].matches('\n').count() + 1;
                }
                seen += 1;
                depth += 1;
            }
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            ']' if depth == 0 => break,
            _ => {}
        }
    }
    start
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "(\n  name: \"t\",\n  scene: \"../slab_layer.ron\",\n  plan: [\n    (0.0, 0.0, 0.0),\n    (0.01, 0.0, 0.0),\n  ],\n  depth: 0.003,\n  tolerance: (lateral: 0.002, depth: 0.002),\n  time_limit: 5.0,\n  pass: (completion: 0.9, mean_deviation: 0.002, max_deviation: 0.004, depth_error: 0.002, collateral: 1e-7, max_force: 2.0, score: 60),\n)";

    #[test]
    fn good_exercise_parses() {
        let e = parse_exercise(GOOD, Path::new("e.ron")).unwrap();
        assert_eq!(e.plan.len(), 2);
        assert_eq!(e.surface_tolerance, 0.002);
    }

    #[test]
    fn bad_values_name_the_field_and_line() {
        let bad = GOOD.replace("lateral: 0.002", "lateral: -0.002");
        let e = parse_exercise(&bad, Path::new("e.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.ron:9: tolerance.lateral"), "{e}");
        let bad = GOOD.replace("depth: 0.002)", "depth: 0.0)");
        let e = parse_exercise(&bad, Path::new("e.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.ron:9: tolerance.depth"), "{e}");
        let bad = GOOD.replace("score: 60", "score: 160");
        let e = parse_exercise(&bad, Path::new("e.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.ron:11: pass.score"), "{e}");
        let bad = GOOD.replace("    (0.01, 0.0, 0.0),\n", "");
        let e = parse_exercise(&bad, Path::new("e.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.ron:4: plan has 1 point"), "{e}");
        let bad = GOOD.replace("time_limit", "time_limt");
        let e = parse_exercise(&bad, Path::new("e.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.ron:10:") && e.contains("time_limt"), "{e}");
    }

    #[test]
    fn plan_points_are_found_by_line() {
        assert_eq!(plan_point_line(GOOD, 0), 5);
        assert_eq!(plan_point_line(GOOD, 1), 6);
        assert_eq!(plan_point_line("(plan: [(0,0,0), (1,(2),3)])", 1), 1);
    }
}
