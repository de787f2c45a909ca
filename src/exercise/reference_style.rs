//! How a reference stroke holds and moves the blade.

/// How the reference stroke holds and moves the blade.
#[derive(Debug, Clone, Copy)]
pub struct ReferenceStyle {
    /// Angle of the blade's spine above the surface, degrees (0: flat, 90: vertical).
    pub tilt_deg: f32,
    /// Tip speed, m/s.
    pub speed: f32,
    /// Height above the surface where the tip starts and finishes, m.
    pub approach: f32,
}

impl Default for ReferenceStyle {
    /// Handle raised 30°, 3 cm/s, 4 mm approach.
    fn default() -> Self {
        ReferenceStyle {
            tilt_deg: 30.0,
            speed: 0.03,
            approach: 0.004,
        }
    }
}
