//! Two-band spherical harmonics for light propagation volumes (seed 002 §5.1, §5.3), and a
//! CPU mirror of one propagation step (`shaders/lpv/propagate.wgsl`) for tests.
//!
//! Coefficient order (c00, c1-1, c10, c11) with the real basis
//! y00 = 1/(2√π), y1-1 = −√3/(2√π)·y, y10 = √3/(2√π)·z, y11 = −√3/(2√π)·x.

use zoo_host::glam::{IVec3, Vec3, Vec4};

/// 1 / (2√π).
pub const Y0: f32 = 0.282_094_8;
/// √3 / (2√π).
pub const Y1: f32 = 0.488_602_5;
/// Clamped-cosine lobe, band 0: √π / 2.
pub const COS0: f32 = 0.886_226_9;
/// Clamped-cosine lobe, band 1: √(π/3).
pub const COS1: f32 = 1.023_326_7;
/// Solid angle of the face of a neighbouring cell opposite the shared one, seen from the
/// source cell's centre (unit cells).
pub const FRONT_SOLID_ANGLE: f32 = 0.400_669_7;
/// Solid angle of each of the four side faces of a neighbouring cell.
pub const SIDE_SOLID_ANGLE: f32 = 0.423_441_35;

/// The SH basis evaluated in unit direction `d`.
pub fn basis(d: Vec3) -> Vec4 {
    Vec4::new(Y0, -Y1 * d.y, Y1 * d.z, -Y1 * d.x)
}

/// SH projection of the clamped cosine lobe max(d · ω, 0) around unit `d`.
pub fn cosine_lobe(d: Vec3) -> Vec4 {
    Vec4::new(COS0, -COS1 * d.y, COS1 * d.z, -COS1 * d.x)
}

/// The six axis directions, +x, -x, +y, -y, +z, -z.
pub const AXES: [IVec3; 6] = [
    IVec3::X,
    IVec3::NEG_X,
    IVec3::Y,
    IVec3::NEG_Y,
    IVec3::Z,
    IVec3::NEG_Z,
];

/// One gather step of one colour channel over an `n`³ grid (index x + n (y + n z)), without
/// occlusion: every cell collects from its six neighbours the intensity they send through
/// its faces (face flux Δω · I(ω_c), re-emitted as a clamped-cosine lobe towards the face).
pub fn propagate(grid: &[Vec4], n: i32) -> Vec<Vec4> {
    let index = |c: IVec3| (c.x + n * (c.y + n * c.z)) as usize;
    let inside = |c: IVec3| c.cmpge(IVec3::ZERO).all() && c.cmplt(IVec3::splat(n)).all();
    let mut out = vec![Vec4::ZERO; grid.len()];
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let cell = IVec3::new(x, y, z);
                let mut sum = Vec4::ZERO;
                for d in AXES {
                    let source = cell - d;
                    if !inside(source) {
                        continue;
                    }
                    sum += gather_from(grid[index(source)], d.as_vec3());
                }
                out[index(cell)] = sum;
            }
        }
    }
    out
}

/// What a cell receives from a neighbour holding `source` that lies at −`d` from it.
pub fn gather_from(source: Vec4, d: Vec3) -> Vec4 {
    let mut sum = Vec4::ZERO;
    let front = source.dot(basis(d)).max(0.0);
    sum += FRONT_SOLID_ANGLE / std::f32::consts::PI * front * cosine_lobe(d);
    for a in AXES.map(|a| a.as_vec3()) {
        if a.dot(d) != 0.0 {
            continue;
        }
        let towards = (d + 0.5 * a).normalize();
        let side = source.dot(basis(towards)).max(0.0);
        sum += SIDE_SOLID_ANGLE / std::f32::consts::PI * side * cosine_lobe(a);
    }
    sum
}

/// Calls `f(direction, solid angle)` for the cells of a `samples` x 2 `samples`
/// latitude-longitude grid over the sphere: a midpoint rule for integrals over directions.
pub fn for_sphere_cells(samples: u32, mut f: impl FnMut(Vec3, f32)) {
    use std::f32::consts::{PI, TAU};
    for i in 0..samples {
        for j in 0..2 * samples {
            let theta = (i as f32 + 0.5) / samples as f32 * PI;
            let phi = (j as f32 + 0.5) / (2 * samples) as f32 * TAU;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            f(d, theta.sin() * (PI / samples as f32).powi(2));
        }
    }
}

/// Total flux an SH intensity distribution emits: ∫ I(ω) dω, clamped at 0 per direction,
/// by numerical integration.
pub fn flux(sh: Vec4, samples: u32) -> f32 {
    let mut sum = 0.0;
    for_sphere_cells(samples, |d, area| sum += sh.dot(basis(d)).max(0.0) * area);
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ f(ω) y(ω) dω by a fine latitude-longitude sum.
    fn project(f: impl Fn(Vec3) -> f32) -> Vec4 {
        let mut sum = Vec4::ZERO;
        for_sphere_cells(400, |d, area| sum += basis(d) * f(d) * area);
        sum
    }

    #[test]
    fn the_clamped_cosine_projection_matches_integration() {
        for d in [Vec3::Z, Vec3::NEG_X, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let numeric = project(|w| w.dot(d).max(0.0));
            let closed = cosine_lobe(d);
            assert!(
                (numeric - closed).abs().max_element() < 2e-3,
                "{d}: {numeric} against {closed}"
            );
        }
        // A basis function projects to itself (orthonormality).
        let b = project(|w| basis(w).y);
        assert!(
            (b - Vec4::new(0.0, 1.0, 0.0, 0.0)).abs().max_element() < 2e-3,
            "{b}"
        );
    }

    #[test]
    fn one_vpl_propagates_symmetrically_and_keeps_its_flux() {
        // An isotropic point of light (band 0 only) in the middle of a 9³ grid.
        let n = 9;
        let centre = (4 + n * (4 + n * 4)) as usize;
        let mut grid = vec![Vec4::ZERO; (n * n * n) as usize];
        grid[centre] = Vec4::new(1.0, 0.0, 0.0, 0.0);
        let start = flux(grid[centre], 64);
        let next = propagate(&grid, n);
        let at = |x: i32, y: i32, z: i32| next[(x + n * (y + n * z)) as usize];
        // The six neighbours receive mirror images of one another.
        let px = at(5, 4, 4);
        let nx = at(3, 4, 4);
        assert!(
            (px.x - nx.x).abs() < 1e-6 && (px.w + nx.w).abs() < 1e-6,
            "{px} {nx}"
        );
        let py = at(4, 5, 4);
        assert!((px.x - py.x).abs() < 1e-6);
        assert!(
            (px.w.abs() - py.y.abs()).abs() < 1e-6,
            "the lobes turn with the axis"
        );
        // Light moves outward: each neighbour's lobe points away from the source.
        assert!(basis(Vec3::X).dot(px) > basis(Vec3::NEG_X).dot(px));
        // Total flux after one step within 15 % of the start (the two-band face scheme is
        // not exactly conservative; measured 0.94).
        let after: f32 = next.iter().map(|c| flux(*c, 64)).sum();
        let ratio = after / start;
        assert!((0.85..1.15).contains(&ratio), "flux ratio {ratio}");
        // Nothing stays at the source or jumps two cells.
        assert_eq!(next[centre], Vec4::ZERO);
        assert_eq!(at(6, 4, 4), Vec4::ZERO);
    }

    /// Why a lit floor lights itself in a volume. Above a uniformly lit plane the exact
    /// radiance is the upper hemisphere: a receiver facing up gets nothing, one facing sideways
    /// half of what one facing down gets, and its two-band projection keeps exactly that
    /// (band 1 / band 0 = 0.866, where the up-facing lookup is zero). The face scheme
    /// re-emits every face's flux as a fresh clamped-cosine lobe, so light spreading sideways
    /// adds band 0 faster than band 1: within a cell of the plane the field is near isotropic.
    #[test]
    fn the_face_scheme_turns_a_lit_planes_light_nearly_isotropic() {
        let n = 17;
        let index = |x: i32, y: i32, z: i32| (x + n * (y + n * z)) as usize;
        let mut step = vec![Vec4::ZERO; (n * n * n) as usize];
        for z in 0..n {
            for x in 0..n {
                step[index(x, 0, z)] = cosine_lobe(Vec3::Y);
            }
        }
        let mut accumulated = step.clone();
        for _ in 0..8 {
            step = propagate(&step, n);
            for (a, s) in accumulated.iter_mut().zip(&step) {
                *a += *s;
            }
        }
        // Irradiance on a receiver with normal `normal` (the lobe around -normal).
        let reading = |cell: Vec4, normal: Vec3| cell.dot(cosine_lobe(-normal));
        // The exact field's projection, for contrast: up 0, sideways 1/2, down 1.
        let exact = project(|w| f32::from(w.y > 0.0));
        assert!(reading(exact, Vec3::Y).abs() < 0.02 * reading(exact, Vec3::NEG_Y));
        let side = reading(exact, Vec3::X) / reading(exact, Vec3::NEG_Y);
        assert!((side - 0.5).abs() < 0.02, "{side}");
        // One cell above the plane, in the middle: up-facing gets 0.9 of sideways (measured
        // 0.90), sideways 0.91 of down-facing.
        let cell = accumulated[index(8, 1, 8)];
        let (up, sideways, down) = (
            reading(cell, Vec3::Y),
            reading(cell, Vec3::X),
            reading(cell, Vec3::NEG_Y),
        );
        eprintln!("above a lit plane: up {up:.3}, sideways {sideways:.3}, down {down:.3}");
        assert!(
            up > 0.8 * sideways && sideways > 0.8 * down,
            "{up} {sideways} {down}"
        );
    }
}
