//! Placement of the cascaded grids (seed 002 §5.5, §6.4.1): each grid, `size` cells a side,
//! is pushed forward along the view so that the camera sits near its back, and moves only by
//! whole cells; cell sizes double from the finest grid out.

use zoo_host::glam::Vec3;

/// One grid: its minimum corner and cell size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub min: Vec3,
    pub cell: f32,
}

/// The cells the grids are pushed forward by, as a fraction of their extent: the camera sits
/// 10 % from the back face.
const FORWARD: f32 = 0.4;

/// `count` grids of `size`³ cells, the finest with cells of `finest_cell`, placed around a
/// camera at `eye` looking along unit `view`.
pub fn place(eye: Vec3, view: Vec3, size: u32, count: u32, finest_cell: f32) -> Vec<Grid> {
    (0..count)
        .map(|k| {
            let cell = finest_cell * (1u32 << k) as f32;
            let extent = cell * size as f32;
            let centre = eye + view * (FORWARD * extent);
            let min = centre - Vec3::splat(extent * 0.5);
            Grid {
                min: (min / cell).floor() * cell,
                cell,
            }
        })
        .collect()
}

/// The finest cell size for a scene whose bounds have diagonal `diagonal`: light in the
/// coarsest of `count` grids travels `reach` times the diagonal in `steps` steps (one cell a
/// step). One-bounce light crosses the scene, and a volume's light goes no further than its
/// steps: coarser cells trade detail for reach.
pub fn finest_cell(diagonal: f32, reach: f32, steps: u32, count: u32) -> f32 {
    let coarsest = diagonal * reach / steps.max(1) as f32;
    (coarsest / (1u32 << count.saturating_sub(1)) as f32).max(1e-4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_move_by_whole_cells_and_double() {
        let view = Vec3::new(0.3, -0.2, -1.0).normalize();
        let grids = place(Vec3::new(1.0, 2.0, 3.0), view, 32, 3, 0.25);
        assert_eq!(grids.len(), 3);
        for (k, g) in grids.iter().enumerate() {
            assert_eq!(g.cell, 0.25 * (1 << k) as f32);
            let whole = g.min / g.cell;
            assert!(
                (whole - whole.round()).abs().max_element() < 1e-4,
                "{whole}"
            );
            // The camera is inside, near the back of the view.
            let extent = g.cell * 32.0;
            let local = (Vec3::new(1.0, 2.0, 3.0) - g.min) / extent;
            assert!(local.cmpge(Vec3::ZERO).all() && local.cmple(Vec3::ONE).all());
        }
        // Small camera moves leave a grid in place or move it by whole cells.
        for step in 0..40 {
            let eye = Vec3::new(1.0 + step as f32 * 0.013, 2.0, 3.0);
            let moved = place(eye, view, 32, 3, 0.25);
            for (a, b) in grids.iter().zip(&moved) {
                let cells = (b.min - a.min) / a.cell;
                assert!(
                    (cells - cells.round()).abs().max_element() < 1e-3,
                    "{cells}"
                );
            }
        }
    }

    #[test]
    fn light_in_the_coarsest_grid_travels_the_reach() {
        let cell = finest_cell(48.0, 0.4, 8, 3);
        assert!((cell * 4.0 * 8.0 - 19.2).abs() < 1e-4, "{cell}");
        // More steps, finer cells at the same reach; no steps, one step's reach.
        assert!((finest_cell(48.0, 0.4, 16, 3) - cell / 2.0).abs() < 1e-6);
        assert!((finest_cell(48.0, 0.5, 0, 1) - 24.0).abs() < 1e-4);
    }
}
