//! The 3D view's resolution while it moves: on a slow adapter (lavapipe, llvmpipe, a
//! browser's SwiftShader) camera and light motion render at fewer pixels, so that it stays at
//! ten frames a second or more; a still view renders at full resolution at once, so the judge
//! and screenshots see every pixel.

use zoo_host::glam::UVec2;

/// The longest frame a moving view should take: ten frames a second.
pub const MOVING_FRAME_MS: f64 = 100.0;
/// The smallest share of the view's side rendered while it moves: software adapters take
/// seconds a frame at full size (SwiftShader in a browser four, for shadow maps).
pub const MIN_SCALE: f32 = 0.125;
/// The scale changes only when the one wanted differs from it by more than this share: a new
/// size reallocates the renderer's targets and restarts techniques' histories, so a noisy
/// frame time must not change it (frame times within about 16 % of the aim keep it).
pub const SCALE_TOLERANCE: f32 = 0.08;

/// The frame time aimed at while the view moves: below [`MOVING_FRAME_MS`] by the tolerance, so
/// that the slowest frames a scale keeps stay within it. Window drawing that does not shrink
/// with the view (a browser's panels on SwiftShader: about 80 ms a frame) makes the frame time
/// follow the scale less than the model assumes, and the scale then rests anywhere in the
/// tolerance's band.
pub const AIM_MS: f64 =
    MOVING_FRAME_MS * (1.0 - SCALE_TOLERANCE as f64) * (1.0 - SCALE_TOLERANCE as f64);

/// How long a view must stay unchanged to count as still: input arrives in bursts, and a frame
/// that saw no change in the middle of a drag must not render every pixel (seconds of a frame
/// on a software adapter).
pub const STILL_AFTER_MS: f64 = 300.0;
/// How many frames in a row must see no change for the view to count as still (where frames
/// take longer than [`STILL_AFTER_MS`]).
pub const STILL_AFTER_FRAMES: u32 = 2;

/// Tells a moving view from a still one by when it last changed.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    last_change_ms: Option<f64>,
    unchanged_frames: u32,
}

impl Motion {
    /// Whether the view moves at `now_ms` (milliseconds on any steady clock), given whether it
    /// `changed` since the last frame: it changed within the last [`STILL_AFTER_MS`] or the
    /// last [`STILL_AFTER_FRAMES`] frames.
    pub fn moving(&mut self, changed: bool, now_ms: f64) -> bool {
        if changed {
            self.last_change_ms = Some(now_ms);
            self.unchanged_frames = 0;
        } else {
            self.unchanged_frames = self.unchanged_frames.saturating_add(1);
        }
        self.last_change_ms.is_some_and(|last| {
            now_ms - last < STILL_AFTER_MS || self.unchanged_frames < STILL_AFTER_FRAMES
        })
    }
}

/// The scale (per side) of the view's pixels rendered, learnt from the frames' times.
#[derive(Debug, Clone)]
pub struct AdaptiveResolution {
    /// The scale the next moving frame renders at.
    moving_scale: f32,
    /// The scale the last frame rendered at.
    rendered_scale: f32,
    /// Whether the last frame moved.
    moving: bool,
}

impl Default for AdaptiveResolution {
    fn default() -> Self {
        Self {
            moving_scale: 1.0,
            rendered_scale: 1.0,
            moving: false,
        }
    }
}

impl AdaptiveResolution {
    /// The size to render a view of `full` pixels at: all of them when the view is still, the
    /// learnt share of them while it moves (the camera or a light changed since last frame).
    pub fn size(&mut self, full: UVec2, moving: bool) -> UVec2 {
        self.moving = moving;
        self.rendered_scale = if moving { self.moving_scale } else { 1.0 };
        let scaled = (full.as_vec2() * self.rendered_scale).round().as_uvec2();
        scaled.max(UVec2::splat(16)).min(full.max(UVec2::splat(16)))
    }

    /// Learns from the time, in milliseconds, that the frame rendered at the last
    /// [`Self::size`] took, if that frame moved (still frames render every pixel whatever
    /// they cost). A frame's cost grows about as its pixels, the square of the scale; each
    /// frame moves the scale at most by half or double toward the one that would take
    /// [`AIM_MS`], so one slow frame (a shader compiled, a map resized, the window
    /// hidden) does not throw it to the floor, and only by more than [`SCALE_TOLERANCE`].
    /// Frames of seconds teach too: that is what software adapters take at full size.
    pub fn frame_took(&mut self, milliseconds: f64) {
        let valid = milliseconds.is_finite() && milliseconds > 0.0;
        if !(self.moving && valid) {
            return;
        }
        let step = ((AIM_MS / milliseconds).sqrt() as f32).clamp(0.5, 2.0);
        let wanted = (self.rendered_scale * step).clamp(MIN_SCALE, 1.0);
        // Full size and the floor are reached whatever the tolerance, or a scale just short
        // of them would stay there.
        let bound = wanted == 1.0 || wanted == MIN_SCALE;
        if bound || (wanted / self.moving_scale - 1.0).abs() > SCALE_TOLERANCE {
            self.moving_scale = wanted;
        }
    }

    /// The scale the last frame rendered at.
    pub fn rendered_scale(&self) -> f32 {
        self.rendered_scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FULL: UVec2 = UVec2::new(800, 600);

    /// Renders moving frames whose cost is `fixed` plus `per_pixel` times their pixels, and
    /// returns the last frame's time.
    fn settle(adaptive: &mut AdaptiveResolution, fixed: f64, per_pixel: f64) -> f64 {
        let mut took = 0.0;
        for _ in 0..20 {
            let size = adaptive.size(FULL, true);
            took = fixed + per_pixel * f64::from(size.x * size.y);
            adaptive.frame_took(took);
        }
        took
    }

    #[test]
    fn a_still_view_renders_every_pixel_and_keeps_what_motion_learnt() {
        let mut adaptive = AdaptiveResolution::default();
        settle(&mut adaptive, 0.0, 1e-3);
        let learnt = adaptive.moving_scale;
        assert!(learnt < 0.5);
        assert_eq!(adaptive.size(FULL, false), FULL);
        assert_eq!(adaptive.rendered_scale(), 1.0);
        adaptive.frame_took(480.0);
        assert_eq!(adaptive.moving_scale, learnt);
    }

    #[test]
    fn jitter_keeps_the_size_and_a_paused_frame_halves_it_once() {
        let mut adaptive = AdaptiveResolution::default();
        let per_pixel = 1200.0 / f64::from(FULL.x * FULL.y);
        settle(&mut adaptive, 0.0, per_pixel);
        let size = adaptive.size(FULL, true);
        // Frame times a few per cent off the aim keep the size.
        for jitter in [0.97, 1.03, 0.95, 1.05] {
            adaptive.frame_took(AIM_MS * jitter);
            assert_eq!(adaptive.size(FULL, true), size);
        }
        adaptive.frame_took(60_000.0);
        let halved = adaptive.size(FULL, true);
        assert!(halved.x.abs_diff(size.x / 2) <= 1, "{halved} from {size}");
        settle(&mut adaptive, 0.0, per_pixel);
        assert_eq!(adaptive.size(FULL, true), size);
    }

    #[test]
    fn frames_of_seconds_shrink_the_view_to_ten_a_second() {
        // SwiftShader: four seconds a frame at full size.
        let mut adaptive = AdaptiveResolution::default();
        let per_pixel = 4000.0 / f64::from(FULL.x * FULL.y);
        let took = settle(&mut adaptive, 0.0, per_pixel);
        assert!(took <= MOVING_FRAME_MS && took > 0.8 * AIM_MS, "{took} ms");
    }

    #[test]
    fn motion_settles_at_ten_frames_a_second_where_pixels_cost() {
        // 1.2 s a frame at full size (the viewer shows sm-pcf at 1.8 s on lavapipe).
        let mut adaptive = AdaptiveResolution::default();
        let per_pixel = 1200.0 / f64::from(FULL.x * FULL.y);
        let took = settle(&mut adaptive, 0.0, per_pixel);
        // Within the scale's tolerance of the aim, under 100 ms.
        assert!(took <= MOVING_FRAME_MS && took > 0.8 * AIM_MS, "{took} ms");
        // A fast adapter keeps every pixel while moving, even after one slow frame left it
        // just short of them.
        let mut fast = AdaptiveResolution::default();
        settle(&mut fast, 2.0, 1e-5);
        assert_eq!(fast.size(FULL, true), FULL);
        fast.frame_took(AIM_MS * 4.0);
        fast.size(FULL, true);
        fast.frame_took(AIM_MS * 0.28);
        let short = fast.size(FULL, true);
        assert!(short.x > FULL.x * 9 / 10 && short.x < FULL.x, "{short}");
        settle(&mut fast, 2.0, 1e-5);
        assert_eq!(fast.size(FULL, true), FULL);
    }

    #[test]
    fn a_frame_without_a_change_in_a_drag_still_moves() {
        let mut motion = Motion::default();
        assert!(!motion.moving(false, 0.0), "never changed: still");
        assert!(motion.moving(true, 1000.0));
        // A frame that saw no input 100 ms into the drag.
        assert!(motion.moving(false, 1100.0));
        assert!(motion.moving(true, 1200.0));
        assert!(motion.moving(false, 1200.0 + STILL_AFTER_MS - 1.0));
        assert!(!motion.moving(false, 1200.0 + STILL_AFTER_MS));
        // Frames of seconds: one frame without a change is a gap, two are a stop.
        assert!(motion.moving(true, 5000.0));
        assert!(motion.moving(false, 8000.0));
        assert!(!motion.moving(false, 11000.0));
    }

    #[test]
    fn a_fixed_cost_under_the_aim_keeps_ten_frames_a_second() {
        // A browser on SwiftShader: 77 ms of window drawing whatever the view's size.
        for full_ms in [300.0, 600.0, 1200.0] {
            let mut adaptive = AdaptiveResolution::default();
            let per_pixel = (full_ms - 77.0) / f64::from(FULL.x * FULL.y);
            let took = settle(&mut adaptive, 77.0, per_pixel);
            assert!(
                took <= MOVING_FRAME_MS,
                "{took} ms ({full_ms} ms at full size)"
            );
        }
    }

    #[test]
    fn a_fixed_cost_above_the_aim_stops_at_the_smallest_scale() {
        let mut adaptive = AdaptiveResolution::default();
        settle(&mut adaptive, 300.0, 1e-4);
        assert_eq!(adaptive.size(FULL, true), UVec2::new(100, 75));
    }

    #[test]
    fn one_slow_frame_halves_the_scale_at_most() {
        let mut adaptive = AdaptiveResolution::default();
        adaptive.size(FULL, true);
        adaptive.frame_took(1900.0);
        assert_eq!(adaptive.size(FULL, true), UVec2::new(400, 300));
        adaptive.frame_took(f64::NAN);
        assert_eq!(adaptive.size(FULL, true), UVec2::new(400, 300));
    }
}
