//! Views: what one eye sees (view and projection matrices), and an orbit camera that
//! produces one for a desktop window or an offscreen image.

use glam::camera::rh::{proj::directx, view};
use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};

/// One eye: world → view and view → clip (wgpu depth range 0..1), and its position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// World to view space.
    pub view: Mat4,
    /// View to clip space.
    pub proj: Mat4,
}

impl View {
    /// The eye's position in world space.
    pub fn eye(&self) -> Vec3 {
        self.view.inverse().w_axis.xyz()
    }

    /// World → clip.
    pub fn view_proj(&self) -> Mat4 {
        self.proj * self.view
    }

    /// Pixel coordinates (origin top left) of world point `p` in a `size` image, or `None`
    /// behind the eye.
    pub fn project(&self, p: Vec3, size: Vec2) -> Option<Vec2> {
        let c = self.view_proj() * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let ndc = c.xy() / c.w;
        Some(Vec2::new(
            (ndc.x * 0.5 + 0.5) * size.x,
            (0.5 - ndc.y * 0.5) * size.y,
        ))
    }

    /// The world-space ray (origin, unit direction) through pixel `px` of a `size` image.
    pub fn ray(&self, px: Vec2, size: Vec2) -> (Vec3, Vec3) {
        let ndc = Vec2::new(px.x / size.x * 2.0 - 1.0, 1.0 - px.y / size.y * 2.0);
        let inv = self.view_proj().inverse();
        let near = inv.project_point3(ndc.extend(0.0));
        let far = inv.project_point3(ndc.extend(1.0));
        (near, (far - near).normalize())
    }
}

/// An orbit camera around a target point, z up (the simulation's up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The point orbited and looked at, m.
    pub target: Vec3,
    /// Distance from the target, m.
    pub distance: f32,
    /// Angle around z from +x towards +y, radians.
    pub yaw: f32,
    /// Elevation above the x-y plane, radians.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
}

impl Camera {
    /// A camera looking at the box `[lo, hi]` from direction (`yaw`, `pitch`), far enough
    /// that the box's bounding sphere fills the view.
    pub fn framing(lo: Vec3, hi: Vec3, yaw: f32, pitch: f32) -> Camera {
        let fov_y = 40f32.to_radians();
        let radius = ((hi - lo).length() * 0.5).max(1e-4);
        Camera {
            target: (lo + hi) * 0.5,
            distance: radius / (fov_y * 0.5).sin() * 1.05,
            yaw,
            pitch,
            fov_y,
        }
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * cy, cp * sy, sp)
    }

    /// The view for an image of aspect ratio `aspect` (width / height).
    pub fn view(&self, aspect: f32) -> View {
        let eye = self.eye();
        // Looking straight down or up, z cannot be the up hint; use the yaw direction.
        let forward = (self.target - eye).normalize_or_zero();
        let up = if forward.cross(Vec3::Z).length_squared() < 1e-8 {
            -Vec3::new(self.yaw.cos(), self.yaw.sin(), 0.0) * forward.z.signum()
        } else {
            Vec3::Z
        };
        let near = (self.distance * 0.01).max(1e-4);
        View {
            view: view::look_at_mat4(eye, self.target, up),
            // wgpu's clip space is Direct3D's: z in [0, 1], y up.
            proj: directx::perspective(self.fov_y, aspect.max(1e-3), near, self.distance * 100.0),
        }
    }

    /// Rotate by `d_yaw`, `d_pitch` radians (pitch kept within ±89°).
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        let limit = 89f32.to_radians();
        self.yaw += d_yaw;
        self.pitch = (self.pitch + d_pitch).clamp(-limit, limit);
    }

    /// Move the target by `right`, `up` fractions of the visible height at the target.
    pub fn pan(&mut self, right: f32, up: f32) {
        let v = self.view(1.0).view.inverse();
        let height = 2.0 * self.distance * (self.fov_y * 0.5).tan();
        self.target += (v.x_axis.xyz() * right + v.y_axis.xyz() * up) * height;
    }

    /// Scale the distance by `factor` (> 1 moves away).
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).max(1e-4);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_projects_to_the_image_centre_and_rays_hit_it() {
        let cam = Camera::framing(Vec3::splat(-1.0), Vec3::splat(1.0), 0.7, 0.4);
        let view = cam.view(1.5);
        let size = Vec2::new(300.0, 200.0);
        let c = view.project(cam.target, size).unwrap();
        assert!((c - size * 0.5).length() < 1e-3, "{c}");
        assert!((view.eye() - cam.eye()).length() < 1e-4);
        let (o, d) = view.ray(Vec2::new(150.0, 100.0), size);
        let to_target = (cam.target - o).normalize();
        assert!(d.dot(to_target) > 0.99999, "{d} vs {to_target}");
        // A point off-centre projects where its ray comes from.
        let p = Vec3::new(0.3, -0.2, 0.5);
        let px = view.project(p, size).unwrap();
        let (o, d) = view.ray(px, size);
        let closest = o + d * (p - o).dot(d);
        assert!((closest - p).length() < 1e-4);
        // Behind the eye: nothing.
        assert!(view.project(cam.eye() * 2.0, size).is_none());
    }

    #[test]
    fn orbit_pan_zoom_and_the_poles() {
        let mut cam = Camera::framing(Vec3::ZERO, Vec3::ONE, 0.0, 0.0);
        let d = cam.distance;
        cam.zoom(2.0);
        assert!((cam.distance - 2.0 * d).abs() < 1e-6);
        cam.zoom(f32::NAN);
        assert!((cam.distance - 2.0 * d).abs() < 1e-6);
        cam.orbit(0.0, 10.0);
        assert!((cam.pitch - 89f32.to_radians()).abs() < 1e-6);
        let t = cam.target;
        cam.pan(0.5, 0.0);
        assert!((cam.target - t).length() > 0.0);
        // Straight down is still a finite view.
        cam.pitch = std::f32::consts::FRAC_PI_2;
        assert!(cam.view(1.0).view_proj().is_finite());
    }
}
