//! What the organ is seen against: the user's room through `XR_FB_passthrough` (Quest 3
//! over Link), a see-through display's own blending (`ALPHA_BLEND`), or an opaque neutral
//! room when neither is offered.

/// The backdrop of the XR view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backdrop {
    /// A passthrough layer under the projection layer (`XR_FB_passthrough`), blended by
    /// the eye images' alpha.
    Passthrough,
    /// The runtime blends by alpha itself (`XR_ENVIRONMENT_BLEND_MODE_ALPHA_BLEND`).
    AlphaBlend,
    /// Opaque: a neutral dark room.
    Opaque,
}

/// The neutral room colour of the opaque backdrop (linear RGB, a dim grey-blue).
pub const ROOM: [f64; 3] = [0.045, 0.05, 0.06];

impl Backdrop {
    /// The best backdrop a runtime offers: passthrough when it has `XR_FB_passthrough`,
    /// else its alpha blend mode, else opaque.
    pub fn choose(fb_passthrough: bool, alpha_blend: bool) -> Backdrop {
        if fb_passthrough {
            Backdrop::Passthrough
        } else if alpha_blend {
            Backdrop::AlphaBlend
        } else {
            Backdrop::Opaque
        }
    }

    /// The eye images' clear colour and alpha: transparent black (premultiplied, so
    /// antialiased edges blend correctly) where the room shows through, else the room.
    pub fn clear(self) -> ([f64; 3], f64) {
        match self {
            Backdrop::Passthrough | Backdrop::AlphaBlend => ([0.0; 3], 0.0),
            Backdrop::Opaque => (ROOM, 1.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passthrough_first_then_alpha_blend_then_an_opaque_room() {
        assert_eq!(Backdrop::choose(true, true), Backdrop::Passthrough);
        assert_eq!(Backdrop::choose(true, false), Backdrop::Passthrough);
        assert_eq!(Backdrop::choose(false, true), Backdrop::AlphaBlend);
        assert_eq!(Backdrop::choose(false, false), Backdrop::Opaque);
        assert_eq!(Backdrop::Passthrough.clear(), ([0.0; 3], 0.0));
        assert_eq!(Backdrop::Opaque.clear(), (ROOM, 1.0));
    }
}
