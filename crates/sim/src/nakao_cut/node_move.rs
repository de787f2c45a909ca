//! Guarded node moves: the adaptive cut displaces nodes (onto the cut boundary, onto the
//! plane, Laplacian smoothing) only when every tet around the node stays valid and good.

use glam::DVec3;

use super::split_order::SplitQuality;
use crate::mass_spring::{MassSpringModel, signed_volume};

/// Quality (reference configuration) of the tets around node `v`.
pub(crate) fn star_quality(model: &MassSpringModel, v: u32) -> SplitQuality {
    tets_quality(model, model.tets_of(v as usize))
}

/// Quality (reference configuration) of `tets`.
pub(crate) fn tets_quality(model: &MassSpringModel, tets: &[u32]) -> SplitQuality {
    let x = model.reference_positions();
    tets.iter()
        .map(|&t| SplitQuality::of_tet(model.tets()[t as usize].map(|i| x[i as usize])))
        .fold(SplitQuality::EMPTY, SplitQuality::merge)
}

/// Move node `v` by `d` (reference and current positions) if `accept(before, after)` holds
/// for the qualities of its star and every tet of the star keeps a positive volume in both
/// configurations; held axes must not change. Returns whether the node moved.
pub(crate) fn try_move(
    model: &mut MassSpringModel,
    v: u32,
    d: DVec3,
    accept: impl Fn(&SplitQuality, &SplitQuality) -> bool,
) -> bool {
    let vi = v as usize;
    let scale = d.length();
    if !(scale > 0.0 && d.is_finite() && model.fixed_axes(vi).allows(d, 1e-12 * scale)) {
        return false;
    }
    let before = star_quality(model, v);
    model.displace(vi, d);
    let valid = model.tets_of(vi).iter().all(|&t| {
        let tet = model.tets()[t as usize];
        let r = signed_volume(tet.map(|i| model.reference_positions()[i as usize]));
        let c = signed_volume(tet.map(|i| model.positions()[i as usize]));
        r > 0.0 && c > 0.0
    });
    if valid && accept(&before, &star_quality(model, v)) {
        return true;
    }
    model.displace(vi, -d);
    false
}
