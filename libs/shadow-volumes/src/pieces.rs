//! The volume work split into pieces whose geometry fits one vertex buffer.
//!
//! The work is a list of units, each one dispatch of the generation's two passes: the
//! triangles stored in world space, then each shadow-casting instance's shared triangles under
//! its placement. A unit whose volume may exceed the buffer is cut into stretches of its
//! triangles and then of its edges (the edges read the weights every triangle stretch wrote
//! before them). Per light, consecutive units the light reaches are packed into pieces whose
//! worst-case vertex counts add up to at most the buffer's capacity; each piece is generated
//! and drawn into the same stencil, where z-fail counts add up across draws.

use std::collections::HashMap;
use std::ops::Range;

use zoo_host::glam::Mat4;
use zoo_host::scene::Scene;

use crate::generation::{FLAG_CASTS, FLAG_PLACED, Part, Volumes};

/// What may emit volume geometry in some stretch of the work: triangles (caps and, per
/// triangle, sides) and edge-face incidences (a side quad each at most).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Emitters {
    pub triangles: u64,
    pub incidences: u64,
}

impl Emitters {
    /// The most vertices they emit for a light: 6 per cap or side where the volume has a far
    /// end (far caps, two far points per side), 3 where it `collapses` to one point (a
    /// directional light extruded to infinity).
    pub fn vertices(self, volumes: Volumes, collapses: bool) -> u64 {
        let per = if collapses { 3 } else { 6 };
        match volumes {
            Volumes::Silhouette => per * (self.triangles + self.incidences),
            // A near cap, a far cap (not where it collapses) and three sides.
            Volumes::PerTriangle => self.triangles * if collapses { 12 } else { 24 },
        }
    }

    /// The most vertices they emit for any light.
    pub fn most_vertices(self, volumes: Volumes) -> u64 {
        self.vertices(volumes, false)
    }
}

impl std::ops::Add for Emitters {
    type Output = Emitters;
    fn add(self, other: Emitters) -> Emitters {
        Emitters {
            triangles: self.triangles + other.triangles,
            incidences: self.incidences + other.incidences,
        }
    }
}

/// One dispatch of the triangle and edge passes.
#[derive(Debug, Clone, Copy)]
pub struct Unit {
    pub part: Part,
    /// The instance whose triangles it places (`None`: the world-space triangles).
    pub object: Option<usize>,
    pub emitters: Emitters,
}

/// The units of a scene's volume work.
#[derive(Debug, Clone, Default)]
pub struct Units {
    /// In the order they must run.
    pub units: Vec<Unit>,
    /// Triangles or edges that alone may need more vertices than a piece holds: their extra
    /// geometry is dropped (one line each per object).
    pub unmet: Vec<String>,
}

/// Whether triangle `t` (flags from [`crate::triangle_flags`]) emits in a part: it casts, and
/// is an instance's when the part places one.
fn emits(flags: &[u32], t: u32, instance: bool) -> bool {
    let f = flags[t as usize];
    f & FLAG_CASTS != 0 && (instance || f & FLAG_PLACED == 0)
}

/// What a part's triangle `t` and edge `e` may emit.
struct PartItems<'a> {
    scene: &'a Scene,
    flags: &'a [u32],
    instance: bool,
}

impl PartItems<'_> {
    fn triangle(&self, t: u32) -> Emitters {
        let triangles = u64::from(emits(self.flags, t, self.instance));
        Emitters {
            triangles,
            incidences: 0,
        }
    }

    fn edge(&self, e: u32) -> Emitters {
        let adjacency = &self.scene.adjacency;
        let edge = adjacency.edges[e as usize];
        let first = adjacency.edge_faces[edge.first_face as usize] >> 1;
        let incidences = match emits(self.flags, first, self.instance) {
            true => u64::from(edge.face_count()),
            false => 0,
        };
        Emitters {
            triangles: 0,
            incidences,
        }
    }

    fn sum(&self, part: &Part) -> Emitters {
        let triangles = part.first_triangle..part.first_triangle + part.triangle_count;
        let edges = part.first_edge..part.first_edge + part.edge_count;
        (triangles.map(|t| self.triangle(t)))
            .chain(edges.map(|e| self.edge(e)))
            .fold(Emitters::default(), |a, b| a + b)
    }
}

/// The parts of `scene`: every stored triangle and edge in world space (instances' triangles
/// left out by their flag), then each shadow-casting instance's, with what they may emit and
/// the instance they place.
pub fn parts(scene: &Scene, flags: &[u32]) -> Vec<Unit> {
    let world = Part {
        to_world: Mat4::IDENTITY,
        first_triangle: 0,
        triangle_count: scene.triangle_count() as u32,
        first_edge: 0,
        edge_count: scene.adjacency.edges.len() as u32,
        instance: 0,
    };
    let items = |instance| PartItems {
        scene,
        flags,
        instance,
    };
    let mut out = vec![Unit {
        part: world,
        object: None,
        emitters: items(false).sum(&world),
    }];
    // Instances of one object share their triangles and edges: sum them once.
    let mut shared: HashMap<(u32, u32), Emitters> = HashMap::new();
    for (i, o) in scene.objects.iter().enumerate() {
        if !(o.is_placed() && o.casts_shadows) {
            continue;
        }
        let edges = &scene.adjacency.object_edges[i];
        let part = Part {
            to_world: o.placement,
            first_triangle: (o.indices.start / 3) as u32,
            triangle_count: (o.indices.len() / 3) as u32,
            first_edge: edges.start,
            edge_count: edges.len() as u32,
            instance: 1,
        };
        let key = (part.first_triangle, part.first_edge);
        let emitters = *shared.entry(key).or_insert_with(|| items(true).sum(&part));
        out.push(Unit {
            part,
            object: Some(i),
            emitters,
        });
    }
    out
}

/// Consecutive stretches of `items` whose emitters (`of`) fit `fits`, and whether some item
/// alone does not (it gets a stretch of its own).
fn stretches(
    items: Range<u32>,
    of: impl Fn(u32) -> Emitters,
    fits: impl Fn(Emitters) -> bool,
) -> (Vec<(Range<u32>, Emitters)>, bool) {
    let mut out = Vec::new();
    let mut over = false;
    let (mut start, mut sum) = (items.start, Emitters::default());
    for item in items.clone() {
        let one = of(item);
        over |= !fits(one);
        if item > start && !fits(sum + one) {
            out.push((start..item, sum));
            (start, sum) = (item, Emitters::default());
        }
        sum = sum + one;
    }
    if items.end > start {
        out.push((start..items.end, sum));
    }
    (out, over)
}

/// The units of `scene`'s volume work (triangle flags `flags`) with `volumes`, for pieces of
/// `capacity` vertices: every part, cut into stretches where it may emit more.
pub fn units(scene: &Scene, flags: &[u32], volumes: Volumes, capacity: u64) -> Units {
    let fits = |e: Emitters| e.most_vertices(volumes) <= capacity;
    let mut out = Units::default();
    for unit in parts(scene, flags) {
        if fits(unit.emitters) {
            out.units.push(unit);
            continue;
        }
        let items = PartItems {
            scene,
            flags,
            instance: unit.part.instance != 0,
        };
        let p = unit.part;
        let triangles = p.first_triangle..p.first_triangle + p.triangle_count;
        let edges = p.first_edge..p.first_edge + p.edge_count;
        let (by_triangle, over_t) = stretches(triangles, |t| items.triangle(t), fits);
        let (by_edge, over_e) = stretches(edges, |e| items.edge(e), fits);
        let stretch = |(range, emitters): (Range<u32>, Emitters), edges: bool| Unit {
            part: Part {
                first_triangle: if edges { 0 } else { range.start },
                triangle_count: if edges { 0 } else { range.len() as u32 },
                first_edge: if edges { range.start } else { 0 },
                edge_count: if edges { range.len() as u32 } else { 0 },
                ..p
            },
            emitters,
            ..unit
        };
        (out.units).extend(by_triangle.into_iter().map(|s| stretch(s, false)));
        (out.units).extend(by_edge.into_iter().map(|s| stretch(s, true)));
        if over_t || over_e {
            let name = unit.object.map_or("the world-space triangles", |i| {
                scene.objects[i].name.as_str()
            });
            out.unmet.push(format!(
                "`{name}` has a {} whose volume alone may need more than the {capacity} \
                 vertices a piece holds; what does not fit is dropped",
                if over_t { "triangle" } else { "edge" }
            ));
        }
    }
    out
}

/// Pieces of one light: the indices of consecutive units whose vertex counts (`vertices`,
/// `None` for a unit the light does not need) add up to at most `capacity`; one piece at least
/// (maybe empty), so that the light's stencil is cleared and resolved.
pub fn pack(
    units: &[Unit],
    capacity: u64,
    vertices: impl Fn(&Unit) -> Option<u64>,
) -> Vec<Vec<u32>> {
    let mut pieces = vec![Vec::new()];
    let mut used = 0;
    for (k, unit) in units.iter().enumerate() {
        let Some(n) = vertices(unit) else { continue };
        let current = pieces.last_mut().expect("one piece at least");
        if used + n > capacity && !current.is_empty() {
            pieces.push(Vec::new());
            used = 0;
        }
        used += n;
        pieces
            .last_mut()
            .expect("one piece at least")
            .push(k as u32);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generation::triangle_flags;

    /// A ground plane (a receiver that casts too) and two instances of a sphere.
    fn scene() -> Scene {
        zoo_host::test_support::scene_from_ron(
            "pieces.ron",
            "(name: \"pieces\",
              camera: (position: (0, 5, 5), target: (0, 0, 0), fov_y_degrees: 50),
              lights: [Point(position: (0, 5, 0), intensity: 10, range: 20)],
              objects: [(mesh: Plane(size: 10), receiver: true),
                        (mesh: Sphere(radius: 0.5, segments: 8, rings: 4), instances: [
                            (translation: (1, 0.5, 0), rotation_degrees: (0, 0, 0), scale: (1, 1, 1)),
                            (translation: (-1, 0.5, 0), rotation_degrees: (0, 0, 0), scale: (1, 1, 1))])])",
        )
    }

    /// Each triangle and edge the units cover, in order: (instance, whether an edge, index).
    fn covered(units: &[Unit]) -> Vec<(Option<usize>, bool, u32)> {
        let mut out = Vec::new();
        for u in units {
            let p = u.part;
            let triangles = p.first_triangle..p.first_triangle + p.triangle_count;
            let edges = p.first_edge..p.first_edge + p.edge_count;
            out.extend(triangles.map(|t| (u.object, false, t)));
            out.extend(edges.map(|e| (u.object, true, e)));
        }
        out
    }

    #[test]
    fn small_pieces_cut_parts_into_stretches_that_cover_them() {
        let scene = scene();
        let flags = triangle_flags(&scene);
        let whole = units(&scene, &flags, Volumes::Silhouette, u64::MAX);
        // The world part and two instances.
        assert_eq!(whole.units.len(), 3);
        assert!(whole.unmet.is_empty());
        let sphere = whole.units[1].emitters;
        assert_eq!(sphere, whole.units[2].emitters);
        assert_eq!(
            sphere.triangles as usize,
            scene.objects[1].indices.len() / 3
        );
        for capacity in [12, 100, 1000] {
            let cut = units(&scene, &flags, Volumes::Silhouette, capacity);
            assert!(cut.unmet.is_empty(), "{capacity}: {:?}", cut.unmet);
            assert!(cut.units.len() > 3, "{capacity}");
            assert!(
                cut.units
                    .iter()
                    .all(|u| u.emitters.most_vertices(Volumes::Silhouette) <= capacity)
            );
            // The same triangles and edges in the same order, triangles first in each part.
            assert_eq!(covered(&cut.units), covered(&whole.units), "{capacity}");
            let sum = |u: &[Unit]| u.iter().fold(Emitters::default(), |a, u| a + u.emitters);
            assert_eq!(sum(&cut.units), sum(&whole.units));
        }
    }

    #[test]
    fn an_edge_no_piece_holds_is_reported() {
        let scene = scene();
        let flags = triangle_flags(&scene);
        // A closed sphere's edges have two faces: 12 vertices of sides at most.
        let cut = units(&scene, &flags, Volumes::Silhouette, 11);
        assert_eq!(cut.unmet.len(), 3, "{:?}", cut.unmet);
        assert!(cut.unmet[0].contains("edge"), "{:?}", cut.unmet);
        // Per triangle, a piece of 24 vertices holds one triangle's volume.
        let per_triangle = units(&scene, &flags, Volumes::PerTriangle, 24);
        assert!(per_triangle.unmet.is_empty(), "{:?}", per_triangle.unmet);
        let cut = units(&scene, &flags, Volumes::PerTriangle, 23);
        assert!(cut.unmet.iter().all(|line| line.contains("triangle")));
    }

    #[test]
    fn pieces_pack_consecutive_units_up_to_the_capacity() {
        let unit = |triangles| Unit {
            part: parts(&scene(), &triangle_flags(&scene()))[0].part,
            object: None,
            emitters: Emitters {
                triangles,
                incidences: 0,
            },
        };
        let work: Vec<Unit> = [1, 2, 3, 4, 1, 1].map(unit).to_vec();
        let vertices = |u: &Unit| Some(u.emitters.vertices(Volumes::Silhouette, true));
        // 3 vertices a triangle: 3 + 6 fit 12, 9 does not join them, 12 alone, 3 + 3.
        assert_eq!(
            pack(&work, 12, vertices),
            [vec![0, 1], vec![2], vec![3], vec![4, 5]]
        );
        // Units a light does not need are left out; one piece at least.
        let odd = |u: &Unit| (u.emitters.triangles % 2 == 1).then_some(3 * u.emitters.triangles);
        assert_eq!(pack(&work, 12, odd), [vec![0, 2], vec![4, 5]]);
        assert_eq!(pack(&work, 12, |_| None), [Vec::<u32>::new()]);
    }

    #[test]
    fn directional_lights_emit_half_the_vertices() {
        let e = Emitters {
            triangles: 5,
            incidences: 7,
        };
        assert_eq!(e.vertices(Volumes::Silhouette, false), 72);
        assert_eq!(e.vertices(Volumes::Silhouette, true), 36);
        assert_eq!(e.vertices(Volumes::PerTriangle, false), 120);
        assert_eq!(e.vertices(Volumes::PerTriangle, true), 60);
        assert_eq!(e.most_vertices(Volumes::Silhouette), 72);
    }
}
