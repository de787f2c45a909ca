//! The one gate of incise's tests (a dev-dependency only): whether a test that finds no
//! GPU adapter, no XR runtime (Monado) or no browser (chromium) skips or fails, and
//! whether a golden picture or a pinned score is compared or rewritten ("blessed").
//!
//! A need's variable (`INCISE_REQUIRE_GPU`, `INCISE_REQUIRE_XR`,
//! `INCISE_REQUIRE_BROWSER`) takes:
//!
//! | value          | `CI` unset or empty | `CI` set (non-empty) |
//! |----------------|---------------------|----------------------|
//! | unset or empty | skip, saying why    | required: fail       |
//! | `0`            | skip, saying why    | skip, saying why     |
//! | `1`            | required: fail      | required: fail       |
//! | anything else  | panic naming the variable and the accepted values | same |
//!
//! An explicit `0` is honoured under CI too: it is a choice written into the job (a
//! runner known to lack a browser, say) and shows in its environment, while CI with the
//! variable unset cannot skip silently. An empty value counts as unset, as in the
//! scripts' `${VAR:-default}`.
//!
//! `INCISE_BLESS` says what a run rewrites instead of comparing: `pictures` (the golden
//! PNGs), `scores` (the pinned scores of the reference strokes) or `all`; unset or empty
//! rewrites nothing. Blessing refuses to run under CI, and any other value panics.
//!
//! The rules are pure functions of the variables' values ([`decide`], [`blessing`]), so
//! their tests set no environment; [`required`], [`skip_or_fail`], [`or_skip`] and
//! [`bless`] read the environment and panic on a value they do not understand.

use std::fmt;

/// The variable that says whether a continuous-integration job is running.
pub const CI: &str = "CI";
/// The variable that says what a run blesses.
pub const BLESS: &str = "INCISE_BLESS";

/// Something a test needs that a machine may lack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// A wgpu adapter (lavapipe will do).
    Gpu,
    /// An OpenXR runtime: Monado, built by scripts/monado.sh.
    Xr,
    /// A headless browser: Debian's chromium.
    Browser,
}

impl Need {
    /// The variable that says whether this need is required.
    pub const fn var(self) -> &'static str {
        match self {
            Need::Gpu => "INCISE_REQUIRE_GPU",
            Need::Xr => "INCISE_REQUIRE_XR",
            Need::Browser => "INCISE_REQUIRE_BROWSER",
        }
    }

    /// What is needed, in words.
    pub const fn what(self) -> &'static str {
        match self {
            Need::Gpu => "a GPU adapter",
            Need::Xr => "an XR runtime (Monado)",
            Need::Browser => "a browser (chromium)",
        }
    }
}

/// What a test does when its need is missing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gate {
    /// It skips, saying why.
    Skip,
    /// It fails: the need's variable is `1`.
    RequiredByVar,
    /// It fails: `CI` is set and the need's variable is unset.
    RequiredByCi,
}

/// What `INCISE_BLESS` rewrites instead of comparing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blessed {
    /// Nothing: compare everything (unset or empty).
    Nothing,
    /// The golden pictures (`pictures`).
    Pictures,
    /// The pinned scores (`scores`).
    Scores,
    /// Both (`all`).
    All,
}

/// A kind of stored expectation a test may bless.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bless {
    /// Golden pictures (tests/golden/*.png, crates/xr/tests/golden/*.png).
    Pictures,
    /// Pinned scores of the shipped reference strokes (tests/golden/score_*.json).
    Scores,
}

impl Blessed {
    /// Whether `kind` is rewritten.
    pub fn covers(self, kind: Bless) -> bool {
        match self {
            Blessed::Nothing => false,
            Blessed::All => true,
            Blessed::Pictures => kind == Bless::Pictures,
            Blessed::Scores => kind == Bless::Scores,
        }
    }
}

/// A gate variable whose value is not understood, or blessing asked for under CI.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GateError {
    /// `var` holds `value`, which is none of `accepted`.
    Unknown {
        /// The variable.
        var: &'static str,
        /// Its value.
        value: String,
        /// The values it takes, in words.
        accepted: String,
    },
    /// `INCISE_BLESS` is `value` while `CI` is set.
    BlessUnderCi {
        /// `INCISE_BLESS`'s value.
        value: String,
    },
}

impl fmt::Display for GateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GateError::Unknown {
                var,
                value,
                accepted,
            } => write!(f, "{var}={value:?} is not understood: {accepted}"),
            GateError::BlessUnderCi { value } => write!(
                f,
                "{BLESS}={value} but CI is set: blessing refuses to run under CI (bless on \
                 a workstation, look at what changed, commit it)"
            ),
        }
    }
}

impl std::error::Error for GateError {}

/// The accepted values of `need`'s variable, in words.
fn gate_values(need: Need) -> String {
    format!(
        "use 1 (missing {} fails the test), 0 (it skips) or leave it unset (it skips, but \
         fails when CI is set)",
        need.what()
    )
}
/// The accepted values of `INCISE_BLESS`, in words.
const BLESS_VALUES: &str = "use pictures, scores or all, or leave it unset (compare, rewrite \
                            nothing)";

/// `Some(v)` for a set, non-empty value.
fn given(value: Option<&str>) -> Option<&str> {
    value.filter(|v| !v.is_empty())
}

/// The gate for `need` from its variable's `value` and `CI`'s (`None`: unset).
pub fn decide(need: Need, value: Option<&str>, ci: Option<&str>) -> Result<Gate, GateError> {
    match given(value) {
        None if given(ci).is_some() => Ok(Gate::RequiredByCi),
        None | Some("0") => Ok(Gate::Skip),
        Some("1") => Ok(Gate::RequiredByVar),
        Some(v) => Err(GateError::Unknown {
            var: need.var(),
            value: v.to_string(),
            accepted: gate_values(need),
        }),
    }
}

/// What is blessed from `INCISE_BLESS`'s `value` and `CI`'s (`None`: unset).
pub fn blessing(value: Option<&str>, ci: Option<&str>) -> Result<Blessed, GateError> {
    let Some(v) = given(value) else {
        return Ok(Blessed::Nothing);
    };
    let blessed = parse_blessed(v)?;
    match given(ci) {
        Some(_) => Err(GateError::BlessUnderCi {
            value: v.to_string(),
        }),
        None => Ok(blessed),
    }
}

/// A non-empty `INCISE_BLESS` value.
fn parse_blessed(v: &str) -> Result<Blessed, GateError> {
    match v {
        "pictures" => Ok(Blessed::Pictures),
        "scores" => Ok(Blessed::Scores),
        "all" => Ok(Blessed::All),
        _ => Err(GateError::Unknown {
            var: BLESS,
            value: v.to_string(),
            accepted: BLESS_VALUES.to_string(),
        }),
    }
}

/// A variable's value from the environment (`None`: unset; not UTF-8: replaced lossily,
/// so it is reported as not understood).
fn env(var: &str) -> Option<String> {
    std::env::var_os(var).map(|v| v.to_string_lossy().into_owned())
}

/// The gate for `need` here; panics when its variable's value is not understood.
#[track_caller]
pub fn gate(need: Need) -> Gate {
    match decide(need, env(need.var()).as_deref(), env(CI).as_deref()) {
        Ok(g) => g,
        Err(e) => panic!("{e}"),
    }
}

/// Whether a missing `need` fails the test here; panics on a value not understood.
#[track_caller]
pub fn required(need: Need) -> bool {
    gate(need) != Gate::Skip
}

/// `need` is missing because `why`: print that the test skips and return, or panic when
/// the need is required here.
#[track_caller]
pub fn skip_or_fail(need: Need, why: impl fmt::Display) {
    act(need, gate(need), why)
}

/// Skip (saying why) or fail by `gate`: `need` is missing because `why`.
#[track_caller]
fn act(need: Need, gate: Gate, why: impl fmt::Display) {
    // A child's stderr ends in a newline; the advice goes on the same line.
    let why = why.to_string();
    let why = why.trim_end();
    match gate {
        Gate::Skip => eprintln!("skipping: {why} (set {}=1 to fail instead)", need.var()),
        Gate::RequiredByVar => panic!("{}=1 but {why}", need.var()),
        Gate::RequiredByCi => panic!(
            "CI is set and {} is unset, so {} is required, but {why} (set {0}=0 to skip)",
            need.var(),
            need.what()
        ),
    }
}

/// The thing `found` holds, or `None` after [`skip_or_fail`] with its error. The need's
/// variable is read either way, so a value not understood fails even where the need is met.
#[track_caller]
pub fn or_skip<T, E: fmt::Display>(need: Need, found: Result<T, E>) -> Option<T> {
    let gate = gate(need);
    match found {
        Ok(t) => Some(t),
        Err(e) => {
            act(need, gate, e);
            None
        }
    }
}

/// Whether this run rewrites `kind` instead of comparing with it; panics on an
/// `INCISE_BLESS` not understood or set under CI.
#[track_caller]
pub fn bless(kind: Bless) -> bool {
    match blessing(env(BLESS).as_deref(), env(CI).as_deref()) {
        Ok(b) => b.covers(kind),
        Err(e) => panic!("{e}"),
    }
}

#[cfg(test)]
mod tests;
