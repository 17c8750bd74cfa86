//! The probe grid: fitted to the scene's box, probes evenly spaced in the middle of the cells
//! of a grid over the box (never on its faces, which are usually floors and the outsides of
//! walls), at least two along every axis so that a lookup always has eight probes around it.

use zoo_host::glam::{UVec3, Vec3};

/// The most probes a grid holds (the `probes` parameter's top, cubed, is below it).
pub const MAX_PROBES: u32 = 48 * 48 * 48;

/// A probe grid: where its first probe's home lies, the spacing along each axis and the probe
/// count along each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeGrid {
    pub origin: Vec3,
    pub spacing: Vec3,
    pub counts: UVec3,
}

impl ProbeGrid {
    /// `probes` probes along the longest side of the box `lo..hi`, one in the middle of each
    /// of as many cells; the other sides as many as keep the spacing (at least two each), the
    /// grid centred on the box. A box with no extent gets a unit grid.
    pub fn fitted(lo: Vec3, hi: Vec3, probes: u32) -> ProbeGrid {
        let probes = probes.max(2);
        let extent = (hi - lo).max(Vec3::ZERO);
        let longest = extent.max_element();
        let spacing = if longest > 0.0 && longest.is_finite() {
            longest / probes as f32
        } else {
            1.0
        };
        let counts = (extent / spacing).ceil().as_uvec3();
        let counts = counts.clamp(UVec3::splat(2), UVec3::splat(probes));
        let span = (counts - 1).as_vec3() * spacing;
        ProbeGrid {
            origin: (lo + hi) * 0.5 - span * 0.5,
            spacing: Vec3::splat(spacing),
            counts,
        }
    }

    /// Probes in the grid.
    pub fn probe_count(&self) -> u32 {
        self.counts.x * self.counts.y * self.counts.z
    }

    /// The home (unmoved position) of the probe at grid coordinates `at`.
    pub fn home(&self, at: UVec3) -> Vec3 {
        self.origin + at.as_vec3() * self.spacing
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_covers_its_box_with_the_longest_side_s_spacing() {
        let grid = ProbeGrid::fitted(Vec3::new(-4.0, 0.0, -2.0), Vec3::new(4.0, 3.0, 2.0), 8);
        assert_eq!(grid.spacing, Vec3::ONE);
        assert_eq!(grid.counts, UVec3::new(8, 3, 4));
        // Each probe in the middle of a 1 m cell: half a cell inside the box's faces.
        assert_eq!(grid.home(UVec3::ZERO), Vec3::new(-3.5, 0.5, -1.5));
        assert_eq!(grid.home(grid.counts - 1), Vec3::new(3.5, 2.5, 1.5));
        assert_eq!(grid.probe_count(), 8 * 3 * 4);
        // A side that is not a whole number of cells: centred, never on the faces.
        let grid = ProbeGrid::fitted(Vec3::ZERO, Vec3::new(10.0, 2.5, 10.0), 10);
        assert_eq!(grid.counts.y, 3);
        assert_eq!(grid.home(UVec3::ZERO).y, 0.25);
    }

    #[test]
    fn flat_and_empty_boxes_still_have_two_probes_an_axis() {
        let flat = ProbeGrid::fitted(Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, 5.0), 5);
        assert_eq!(flat.counts, UVec3::new(5, 2, 5));
        assert_eq!(flat.spacing, Vec3::splat(2.0));
        // Astride the plane, a probe a side.
        assert!((flat.home(UVec3::ZERO).y + 1.0).abs() < 1e-6);
        let empty = ProbeGrid::fitted(Vec3::ONE, Vec3::ONE, 6);
        assert_eq!((empty.counts, empty.spacing), (UVec3::splat(2), Vec3::ONE));
        let top = ProbeGrid::fitted(Vec3::ZERO, Vec3::splat(1.0), 48);
        assert_eq!(top.probe_count(), MAX_PROBES);
    }
}
