//! Training exercises (issue 10): a task on a scene (a planned incision with a target
//! depth and tolerance band, a time limit, pass thresholds), objective metrics of an
//! attempt computed from the simulation state, a score, a one-page HTML report and a
//! local history of attempts. Definitions: docs/scoring.md.

mod attempt;
mod band;
mod cut_reading;
mod history;
pub mod live;
mod load;
mod metrics;
mod model;
mod plan;
mod pose_recording;
mod reference;
mod reference_blade;
mod reference_style;
mod report_html;
mod result;
mod result_card;
mod score;

pub use attempt::{Attempt, ExerciseOptions, run_exercise, save_attempt, score_attempt};
pub use history::{
    HistoryEntry, append as append_history, read as read_history, table as history_table, utc_now,
};
pub use live::{AttemptBody, Finished, LiveExercise, StrokeSource};
pub use load::{LoadedExercise, exercise_scene, load_exercise, parse_exercise};
pub use metrics::{Metrics, STROKE_GAP_FRAMES, ToolFrame, compute as compute_metrics};
pub use model::{Exercise, PassThresholds, Tolerance};
pub use plan::{Plan, PlanCoords, PlanSample, RestSurface};
pub use pose_recording::PoseRecording;
pub use reference::{reference_stroke, write_reference_stroke};
pub use reference_style::ReferenceStyle;
pub use report_html::CutImages;
pub use result::ExerciseResult;
pub use result_card::{BANNER, CARD_SIZE, FAIL_COLOUR, PASS_COLOUR, Standing, render_card};
pub use score::{Check, Verdict, WEIGHTS, Weights, judge};
