//! The gate's rules as pure functions of (the variable's value, `CI`'s value).

use super::*;

const NEEDS: [Need; 3] = [Need::Gpu, Need::Xr, Need::Browser];

/// `decide` for every need, which must agree.
fn all(value: Option<&str>, ci: Option<&str>) -> Result<Gate, GateError> {
    let first = decide(Need::Gpu, value, ci);
    for need in NEEDS {
        let d = decide(need, value, ci);
        assert_eq!(d.is_ok(), first.is_ok(), "{need:?}");
        if let Ok(g) = d {
            assert_eq!(Ok(g), first, "{need:?}");
        }
    }
    first
}

#[test]
fn unset_or_empty_skips_without_ci() {
    assert_eq!(all(None, None), Ok(Gate::Skip));
    assert_eq!(all(Some(""), None), Ok(Gate::Skip));
    assert_eq!(all(None, Some("")), Ok(Gate::Skip));
}

#[test]
fn unset_or_empty_is_required_under_ci() {
    assert_eq!(all(None, Some("true")), Ok(Gate::RequiredByCi));
    assert_eq!(all(Some(""), Some("1")), Ok(Gate::RequiredByCi));
    // Any non-empty CI counts, as in scripts/test.sh's `[ -n "${CI:-}" ]`.
    assert_eq!(all(None, Some("false")), Ok(Gate::RequiredByCi));
}

#[test]
fn zero_skips_even_under_ci() {
    assert_eq!(all(Some("0"), None), Ok(Gate::Skip));
    assert_eq!(all(Some("0"), Some("true")), Ok(Gate::Skip));
}

#[test]
fn one_is_required_with_or_without_ci() {
    assert_eq!(all(Some("1"), None), Ok(Gate::RequiredByVar));
    assert_eq!(all(Some("1"), Some("true")), Ok(Gate::RequiredByVar));
}

#[test]
fn any_other_value_is_an_error_naming_the_variable_and_the_values() {
    for value in ["true", "yes", "2", " 1", "1 ", "false", "on"] {
        for ci in [None, Some("true")] {
            for need in NEEDS {
                let e = decide(need, Some(value), ci).unwrap_err();
                let msg = e.to_string();
                assert!(
                    msg.contains(&format!("{}=\"{value}\"", need.var())),
                    "{msg}"
                );
                assert!(
                    msg.contains("use 1") && msg.contains("0 (it skips)"),
                    "{msg}"
                );
                assert!(msg.contains(need.what()), "{msg}");
            }
        }
    }
}

#[test]
fn each_need_has_its_own_variable() {
    assert_eq!(Need::Gpu.var(), "INCISE_REQUIRE_GPU");
    assert_eq!(Need::Xr.var(), "INCISE_REQUIRE_XR");
    assert_eq!(Need::Browser.var(), "INCISE_REQUIRE_BROWSER");
}

#[test]
fn unset_or_empty_bless_blesses_nothing_even_under_ci() {
    for ci in [None, Some(""), Some("true")] {
        assert_eq!(blessing(None, ci), Ok(Blessed::Nothing));
        assert_eq!(blessing(Some(""), ci), Ok(Blessed::Nothing));
    }
}

#[test]
fn bless_names_what_it_rewrites() {
    let covers = |v: &str| {
        let b = blessing(Some(v), None).unwrap();
        (b.covers(Bless::Pictures), b.covers(Bless::Scores))
    };
    assert_eq!(covers("pictures"), (true, false));
    assert_eq!(covers("scores"), (false, true));
    assert_eq!(covers("all"), (true, true));
    assert!(!Blessed::Nothing.covers(Bless::Pictures));
    assert!(!Blessed::Nothing.covers(Bless::Scores));
}

#[test]
fn bless_refuses_to_run_under_ci() {
    for v in ["pictures", "scores", "all"] {
        let e = blessing(Some(v), Some("true")).unwrap_err();
        assert_eq!(e, GateError::BlessUnderCi { value: v.into() });
        assert!(
            e.to_string().contains("blessing refuses to run under CI"),
            "{e}"
        );
    }
}

#[test]
fn an_unknown_bless_value_is_an_error_listing_the_values() {
    // `1` was the old spelling: it must not silently bless (or not bless) anything now.
    for v in ["1", "0", "true", "golden", "Pictures"] {
        for ci in [None, Some("true")] {
            let msg = blessing(Some(v), ci).unwrap_err().to_string();
            assert!(msg.contains(&format!("INCISE_BLESS=\"{v}\"")), "{msg}");
            assert!(msg.contains("pictures, scores or all"), "{msg}");
        }
    }
}

/// (Reads the need's variable, which must be understood where this test runs.)
#[test]
fn or_skip_passes_what_was_found() {
    assert_eq!(or_skip(Need::Gpu, Ok::<_, String>(7)), Some(7));
}
