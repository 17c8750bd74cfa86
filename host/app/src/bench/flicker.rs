//! Temporal stability: how often a technique's visibility flips between consecutive frames at
//! pixels whose reference visibility did not change.

/// One frame's visibility (technique and hard reference) for every light.
pub struct FrameVisibility {
    /// Per light: technique visibility per pixel.
    pub technique: Vec<Vec<f32>>,
    /// Per light: reference hard visibility per pixel, `None` where the light does not reach.
    pub reference: Vec<Vec<Option<bool>>>,
}

/// Fraction of stable pixels (the light reaches them in both frames and the reference did not
/// change) whose technique visibility crossed 0.5 between `previous` and `current`; `None`
/// when no pixel is stable.
pub fn flip_fraction(previous: &FrameVisibility, current: &FrameVisibility) -> Option<f64> {
    let (mut stable, mut flipped) = (0usize, 0usize);
    for light in 0..current.technique.len().min(previous.technique.len()) {
        let pairs = previous.reference[light]
            .iter()
            .zip(&current.reference[light]);
        for (i, (before, now)) in pairs.enumerate() {
            let (Some(before), Some(now)) = (before, now) else {
                continue;
            };
            if before != now {
                continue;
            }
            stable += 1;
            let was_lit = previous.technique[light][i] >= 0.5;
            let is_lit = current.technique[light][i] >= 0.5;
            flipped += usize::from(was_lit != is_lit);
        }
    }
    (stable > 0).then(|| flipped as f64 / stable as f64)
}

/// Accumulates the flicker index frame by frame, keeping only the previous frame.
#[derive(Default)]
pub struct Flicker {
    previous: Option<FrameVisibility>,
    sum: f64,
    pairs: usize,
}

impl Flicker {
    /// Adds the next frame.
    pub fn push(&mut self, frame: FrameVisibility) {
        if let Some(previous) = &self.previous
            && let Some(fraction) = flip_fraction(previous, &frame)
        {
            self.sum += fraction;
            self.pairs += 1;
        }
        self.previous = Some(frame);
    }

    /// The mean flip fraction over consecutive frame pairs (0 with fewer than two frames).
    pub fn index(&self) -> f64 {
        if self.pairs == 0 {
            0.0
        } else {
            self.sum / self.pairs as f64
        }
    }
}

/// The flicker index of a sequence of frames.
pub fn flicker_index(frames: impl IntoIterator<Item = FrameVisibility>) -> f64 {
    let mut flicker = Flicker::default();
    for frame in frames {
        flicker.push(frame);
    }
    flicker.index()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(technique: &[f32], reference: &[Option<bool>]) -> FrameVisibility {
        FrameVisibility {
            technique: vec![technique.to_vec()],
            reference: vec![reference.to_vec()],
        }
    }

    #[test]
    fn identical_frames_do_not_flicker() {
        let f = || {
            frame(
                &[1.0, 0.0, 0.3, 1.0],
                &[Some(true), Some(false), Some(false), None],
            )
        };
        assert_eq!(flicker_index([f(), f(), f()]), 0.0);
    }

    #[test]
    fn flips_count_only_where_the_reference_is_stable() {
        let a = frame(
            &[1.0, 0.0, 1.0, 0.0],
            &[Some(true), Some(false), Some(true), Some(false)],
        );
        // Pixel 0 flips with a stable reference (counts); pixel 2 flips because the reference
        // changed (does not count); pixel 3 is not reached in the second frame.
        let b = frame(
            &[0.0, 0.0, 0.0, 1.0],
            &[Some(true), Some(false), Some(false), None],
        );
        assert_eq!(flip_fraction(&a, &b), Some(0.5));
        assert_eq!(flicker_index([a, b]), 0.5);
        let none = || frame(&[1.0], &[None]);
        assert_eq!(flip_fraction(&none(), &none()), None);
        assert_eq!(flicker_index([none(), none()]), 0.0);
    }
}
