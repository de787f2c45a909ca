//! The mouse scalpel without a window: cursor rays in, the blade's pose out, once per
//! simulated frame. Nothing here knows winit, so tests feed it synthetic events.
//!
//! The plane: **horizontal** (normal +z, the simulation's up) through the tissue point
//! picked when the left button goes down. A scalpel is drawn along the tissue surface,
//! so the blade keeps its height while the cursor moves however the camera looks; a
//! camera-facing plane would move the blade toward and away from the tissue as the
//! cursor crosses the screen of an oblique view. Before the first pick the plane is the
//! top of the tissue's rest bounds.
//!
//! The blade stands vertical (tool +z = world +z, PHYSICS.md §1.5 tool frame), its spine
//! (tool +x, toward the handle) turning toward the direction it moves (handle leading, as
//! in a scripted incision) at a bounded rate. While the left button is held the edge's
//! lowest point descends to `depth` below the plane; released, it rises to `hover` above
//! it. The blade follows its target at bounded speeds, so a jump of the cursor becomes a
//! fast stroke, not a teleport through the tissue.

use glam::{Quat, Vec2, Vec3};
use incise_scalpel::Tool;
use incise_sim::contact::ToolPose;

/// What the input needs of the blade's shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeGeometry {
    /// Height of the tip (tool origin) above the cutting edge's lowest point, m.
    pub drop: f32,
    /// Deepest allowed depth: the blade's height from that lowest point to its spine, m
    /// (deeper, the spine would enter the tissue).
    pub max_depth: f32,
}

impl BladeGeometry {
    /// The geometry of `tool`'s blade.
    pub fn of(tool: &Tool) -> BladeGeometry {
        let lowest = tool.edge().iter().map(|p| p.y).fold(0.0, f32::min);
        let spine = tool.outline().iter().map(|p| p.y).fold(0.0, f32::max);
        BladeGeometry {
            drop: -lowest,
            max_depth: spine - lowest,
        }
    }
}

/// How the blade follows the mouse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalpelFeel {
    /// Height of the edge's lowest point above the plane while the button is up, m.
    pub hover: f32,
    /// Depth change per wheel notch, m.
    pub depth_step: f32,
    /// Largest horizontal blade speed, m/s.
    pub speed: f32,
    /// Largest vertical blade speed (descent and lift), m/s.
    pub sink_speed: f32,
    /// Largest turning rate of the heading, rad/s.
    pub turn_rate: f32,
    /// Horizontal motion in one frame below which the heading does not turn, m.
    pub turn_threshold: f32,
}

impl Default for ScalpelFeel {
    fn default() -> Self {
        ScalpelFeel {
            hover: 0.005,
            depth_step: 0.0005,
            speed: 0.1,
            sink_speed: 0.02,
            turn_rate: std::f32::consts::PI,
            turn_threshold: 1e-4,
        }
    }
}

/// The mouse scalpel's state.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalpelInput {
    geometry: BladeGeometry,
    feel: ScalpelFeel,
    /// Height of the horizontal plane, m.
    plane_z: f32,
    /// Where the cursor's ray meets the plane.
    target: Vec2,
    /// Blade heading: angle of tool +x from world +x about +z, radians.
    heading: f32,
    cutting: bool,
    depth: f32,
    /// Extra height while parked (before the mouse first moves the blade), m.
    parked: f32,
    pose: ToolPose,
}

/// Where the ray `origin + s·dir` (s > 0) meets the plane `z = plane_z`; `None` when it
/// runs parallel to it or away from it.
pub fn ray_plane(origin: Vec3, dir: Vec3, plane_z: f32) -> Option<Vec2> {
    if dir.z.abs() < 1e-6 {
        return None;
    }
    let s = (plane_z - origin.z) / dir.z;
    (s > 0.0 && s.is_finite()).then(|| (origin + dir * s).truncate())
}

/// `a − b` wrapped into (−π, π].
fn angle_diff(a: f32, b: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI { d - TAU } else { d }
}

impl ScalpelInput {
    /// A blade hovering over `over` (the plane through it), heading `heading` radians,
    /// cut depth half the blade's usable depth, at most 5 mm.
    pub fn new(geometry: BladeGeometry, feel: ScalpelFeel, over: Vec3, heading: f32) -> Self {
        let mut s = ScalpelInput {
            geometry,
            feel,
            plane_z: over.z,
            target: over.truncate(),
            heading,
            cutting: false,
            depth: (0.5 * geometry.max_depth).min(0.005),
            parked: 0.0,
            pose: ToolPose::new(Vec3::ZERO, Quat::IDENTITY),
        };
        s.pose = s.target_pose();
        s
    }

    /// Park the blade `height` m above its hover height, out of the tissue's way, until
    /// the cursor first moves it (so a scene nobody cuts runs as it does headless).
    pub fn park(&mut self, height: f32) {
        self.parked = height.max(0.0);
        self.pose = self.target_pose();
    }

    /// Whether the blade waits parked for the cursor.
    pub fn is_parked(&self) -> bool {
        self.parked > 0.0
    }

    /// Take the blade over from wherever something else put it (the scene's stroke): it
    /// continues from `pose`, its heading that of the pose's spine.
    pub fn take_over(&mut self, pose: ToolPose) {
        let spine = pose.rotation * Vec3::X;
        if spine.truncate().length() > 1e-6 {
            self.heading = spine.y.atan2(spine.x);
        }
        self.pose = pose;
    }

    /// The cursor's ray moved: the blade's target follows on the plane (unchanged when the
    /// ray misses the plane).
    pub fn cursor(&mut self, origin: Vec3, dir: Vec3) {
        if let Some(p) = ray_plane(origin, dir, self.plane_z) {
            self.target = p;
            self.parked = 0.0;
        }
    }

    /// The left button went down with the cursor's ray meeting the tissue at `tissue`
    /// (`None`: it missed, nothing starts). The plane moves to that point's height and
    /// the blade starts descending there; returns whether a cut started.
    pub fn press(&mut self, tissue: Option<Vec3>) -> bool {
        let Some(p) = tissue else { return false };
        self.plane_z = p.z;
        self.target = p.truncate();
        self.cutting = true;
        self.parked = 0.0;
        true
    }

    /// The left button came up: the blade lifts.
    pub fn release(&mut self) {
        self.cutting = false;
    }

    /// A wheel turn of `notches` (positive: away from the user): shallower by one
    /// `depth_step` a notch, deeper toward the user; kept within [0, max depth]. Returns the
    /// new depth, m.
    pub fn wheel(&mut self, notches: f32) -> f32 {
        self.set_depth(self.depth - notches * self.feel.depth_step)
    }

    /// Set the cut depth (clamped to [0, max depth]); returns it, m.
    pub fn set_depth(&mut self, depth: f32) -> f32 {
        if depth.is_finite() {
            self.depth = depth.clamp(0.0, self.geometry.max_depth);
        }
        self.depth
    }

    /// Depth of the edge's lowest point below the plane while cutting, m.
    pub fn depth(&self) -> f32 {
        self.depth
    }

    /// The blade's geometry.
    pub fn geometry(&self) -> BladeGeometry {
        self.geometry
    }

    /// Whether the left button is held on the tissue.
    pub fn cutting(&self) -> bool {
        self.cutting
    }

    /// The blade's pose as of the last [`ScalpelInput::advance`].
    pub fn pose(&self) -> ToolPose {
        self.pose
    }

    /// The height of the plane, m.
    pub fn plane_z(&self) -> f32 {
        self.plane_z
    }

    /// Where the blade goes: over the target, tip `drop` above the edge's lowest point,
    /// which is `depth` below the plane while cutting or `hover` above it.
    pub fn target_pose(&self) -> ToolPose {
        let edge_z = if self.cutting {
            self.plane_z - self.depth
        } else {
            self.plane_z + self.feel.hover + self.parked
        };
        ToolPose::new(
            self.target.extend(edge_z + self.geometry.drop),
            Quat::from_rotation_z(self.heading),
        )
    }

    /// Move the blade toward its target for one frame of `dt` seconds (speeds bounded,
    /// heading turned toward the horizontal motion) and return its new pose.
    pub fn advance(&mut self, dt: f32) -> ToolPose {
        let goal = self.target_pose().position;
        let at = self.pose.position;
        let flat = goal.truncate() - at.truncate();
        let step = flat.clamp_length_max(self.feel.speed * dt);
        if step.length() > self.feel.turn_threshold {
            let want = step.y.atan2(step.x);
            let turn = angle_diff(want, self.heading);
            let max = self.feel.turn_rate * dt;
            self.heading = angle_diff(self.heading + turn.clamp(-max, max), 0.0);
        }
        // Above the hover height (parked) the blade comes down at the horizontal speed,
        // no lower than that height; near and in the tissue at the sink speed.
        let hover_tip = self.plane_z + self.feel.hover + self.geometry.drop;
        let z = if goal.z < at.z && at.z > hover_tip {
            (at.z - self.feel.speed * dt).max(goal.z.max(hover_tip))
        } else {
            let slow = self.feel.sink_speed * dt;
            at.z + (goal.z - at.z).clamp(-slow, slow)
        };
        self.pose = ToolPose::new(
            (at.truncate() + step).extend(z),
            Quat::from_rotation_z(self.heading),
        );
        self.pose
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use incise_xr::Camera;

    /// The No. 10 blade: edge 5 mm below the tip, spine 3.5 mm above it.
    const BLADE: BladeGeometry = BladeGeometry {
        drop: 0.005,
        max_depth: 0.0085,
    };

    #[test]
    fn the_built_in_blade_has_the_hand_measured_geometry() {
        let g = BladeGeometry::of(&crate::scene::hand_tool::default_tool().unwrap());
        assert!((g.drop - BLADE.drop).abs() < 1e-7, "{g:?}");
        assert!((g.max_depth - BLADE.max_depth).abs() < 1e-7, "{g:?}");
    }

    #[test]
    fn rays_meet_the_horizontal_plane_where_hand_computation_says() {
        // From (0, 0, 1) along (0.6, 0, -0.8) to z = 0.2: s = 0.8 / 0.8 = 1.
        let p = ray_plane(Vec3::Z, Vec3::new(0.6, 0.0, -0.8), 0.2).unwrap();
        assert!((p - Vec2::new(0.6, 0.0)).length() < 1e-6, "{p}");
        // Parallel, or pointing away: no point.
        assert!(ray_plane(Vec3::Z, Vec3::X, 0.2).is_none());
        assert!(ray_plane(Vec3::Z, Vec3::new(0.6, 0.0, 0.8), 0.2).is_none());
    }

    #[test]
    fn cursor_to_ray_to_plane_to_pose_from_a_camera_straight_above() {
        // A camera 0.1 m above (0.04, 0.02, 0.02) looking straight down, yaw 0: the
        // image's up is +x. Half the image height covers 0.1·tan 20° at the target.
        let target = Vec3::new(0.04, 0.02, 0.02);
        let cam = Camera {
            target,
            distance: 0.1,
            yaw: 0.0,
            pitch: std::f32::consts::FRAC_PI_2,
            fov_y: 40f32.to_radians(),
        };
        let size = Vec2::new(200.0, 100.0);
        let view = cam.view(2.0);
        let mut s = ScalpelInput::new(BLADE, ScalpelFeel::default(), target, 0.0);
        // The image centre picks the point under the camera.
        let (o, d) = view.ray(Vec2::new(100.0, 50.0), size);
        assert!(s.press(Some(target)));
        s.cursor(o, d);
        let goal = s.target_pose();
        // Cutting 4.25 mm deep (the default: half the 8.5 mm blade, under the 5 mm cap).
        assert!((s.depth() - 0.00425).abs() < 1e-7);
        let want = Vec3::new(0.04, 0.02, 0.02 - 0.00425 + 0.005);
        assert!((goal.position - want).length() < 1e-5, "{}", goal.position);
        // The top edge's middle: 0.1·tan 20° = 36.397 mm further along +x.
        let (o, d) = view.ray(Vec2::new(100.0, 0.0), size);
        s.cursor(o, d);
        let goal = s.target_pose().position;
        let off = 0.1 * 20f32.to_radians().tan();
        assert!((off - 0.036397).abs() < 1e-5);
        assert!(
            (goal.truncate() - Vec2::new(0.04 + off, 0.02)).length() < 1e-5,
            "{goal}"
        );
        // Released: the edge rises to 5 mm above the plane, the tip 5 mm above that.
        s.release();
        assert!((s.target_pose().position.z - (0.02 + 0.005 + 0.005)).abs() < 1e-6);
    }

    #[test]
    fn the_blade_follows_at_bounded_speed_and_turns_toward_its_motion() {
        let feel = ScalpelFeel::default();
        let start = Vec3::new(0.0, 0.0, 0.02);
        let mut s = ScalpelInput::new(BLADE, feel, start, 0.0);
        let hover_z = 0.02 + 0.005 + 0.005;
        assert!((s.pose().position - Vec3::new(0.0, 0.0, hover_z)).length() < 1e-7);
        assert!(s.press(Some(start)));
        // Target 1 cm along +y at the same height.
        s.cursor(Vec3::new(0.0, 0.01, 1.0), -Vec3::Z);
        let dt = 0.01;
        let p = s.advance(dt).position;
        // 0.1 m/s × 10 ms = 1 mm along y; 0.02 m/s × 10 ms = 0.2 mm down.
        assert!(
            (p - Vec3::new(0.0, 0.001, hover_z - 0.0002)).length() < 1e-7,
            "{p}"
        );
        // The heading turned toward +y by π rad/s × 10 ms.
        let spine = s.pose().rotation * Vec3::X;
        let a = spine.y.atan2(spine.x);
        assert!((a - std::f32::consts::PI * dt).abs() < 1e-5, "{a}");
        // Long enough: at the target, edge 4.25 mm deep. The heading turned only while the
        // blade moved: 10 frames of 1 mm, π rad/s × 10 ms each.
        for _ in 0..200 {
            s.advance(dt);
        }
        let p = s.pose().position;
        assert!(
            (p - Vec3::new(0.0, 0.01, 0.02 - 0.00425 + 0.005)).length() < 1e-6,
            "{p}"
        );
        let spine = s.pose().rotation * Vec3::X;
        let a = spine.y.atan2(spine.x);
        assert!((a - 0.1 * std::f32::consts::PI).abs() < 1e-4, "{a}");
        // A miss starts nothing.
        s.release();
        assert!(!s.press(None) && !s.cutting());
    }

    #[test]
    fn a_parked_blade_waits_above_until_the_cursor_moves_it() {
        let over = Vec3::new(0.0, 0.0, 0.02);
        let mut s = ScalpelInput::new(BLADE, ScalpelFeel::default(), over, 0.0);
        s.park(0.1);
        let parked_z = 0.02 + 0.005 + 0.1 + 0.005;
        assert!(s.is_parked());
        assert!((s.pose().position.z - parked_z).abs() < 1e-6);
        assert!((s.advance(0.01).position.z - parked_z).abs() < 1e-6);
        // A ray that misses the plane leaves it parked; one that meets it brings it down.
        s.cursor(Vec3::Z, Vec3::X);
        assert!(s.is_parked());
        s.cursor(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z);
        assert!(!s.is_parked());
        // Down at 0.1 m/s (1 mm in 10 ms) while above the hover height, and no lower.
        let z = s.advance(0.01).position.z;
        assert!((z - (parked_z - 0.001)).abs() < 1e-6, "{z}");
        for _ in 0..200 {
            s.advance(0.01);
        }
        assert!((s.pose().position.z - (0.02 + 0.005 + 0.005)).abs() < 1e-6);
    }

    #[test]
    fn the_wheel_moves_the_depth_in_steps_within_the_blade() {
        let mut s = ScalpelInput::new(BLADE, ScalpelFeel::default(), Vec3::ZERO, 0.0);
        let d0 = s.depth();
        // Toward the user (negative notches): 0.5 mm deeper a notch.
        assert!((s.wheel(-2.0) - (d0 + 0.001)).abs() < 1e-7);
        // Never below the spine's reach, never above the surface.
        assert_eq!(s.wheel(-100.0), BLADE.max_depth);
        assert_eq!(s.wheel(100.0), 0.0);
        assert_eq!(s.set_depth(f32::NAN), 0.0);
        assert_eq!(s.set_depth(0.003), 0.003);
    }
}
