//! The pictures `incise run --screenshot-every N` takes of a body: the XPBD solver's
//! screenshots (its tool and an exercise's plan drawn), or any method's tet views.

use super::screenshots::Screenshots;
use super::view_pictures::ViewPictures;

/// An offscreen renderer for one run's body.
pub enum RunPictures {
    /// Of an XPBD solver (CPU or GPU), with its tool and decal.
    Solver(Box<Screenshots>),
    /// Of any method's tet view, with the heat map of its quantity.
    Views(Box<ViewPictures>),
}
