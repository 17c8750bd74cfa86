//! Free space on the shadow atlas's pages, for placing tiles around the ones a frame keeps.
//! Each page is a quadtree whose level-`l` nodes are the aligned squares of side
//! `page_size >> l` (a tile of tier `l`), numbered along the Z-order curve, so a free square
//! of any tier is found by descending the tree instead of scanning texels.

use zoo_host::glam::UVec2;

use crate::atlas_pages::{AtlasLimits, MapTile};

/// What a node's square holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Node {
    /// Nothing: every square below it is free too.
    Free,
    /// Some tiles, and room for more somewhere below.
    Partial,
    /// One tile, or tiles covering it whole.
    Full,
}

/// The occupied squares of every page of an atlas.
pub struct AtlasSpace {
    limits: AtlasLimits,
    /// Per page (made when first touched), per level, the nodes in Z-order.
    pages: Vec<Option<Vec<Vec<Node>>>>,
}

impl AtlasSpace {
    /// An empty atlas of `limits`' pages, with tiles down to its largest tier.
    pub fn new(limits: AtlasLimits) -> AtlasSpace {
        AtlasSpace {
            limits,
            pages: vec![None; limits.max_pages as usize],
        }
    }

    fn page(&mut self, page: usize) -> &mut Vec<Vec<Node>> {
        let levels = self.limits.max_tier() + 1;
        self.pages[page].get_or_insert_with(|| {
            (0..levels)
                .map(|level| vec![Node::Free; 1 << (2 * level)])
                .collect()
        })
    }

    /// Marks `tile` (of tier `tier`) as used; false, changing nothing, when it is not an
    /// aligned square of that tier on a page of the atlas or overlaps a tile already placed.
    pub fn reserve(&mut self, tile: MapTile, tier: u32) -> bool {
        if tier > self.limits.max_tier() {
            return false;
        }
        let size = self.limits.tile_size(tier);
        let aligned = tile.size == size
            && size > 0
            && tile.page < self.limits.max_pages
            && (tile.origin.to_array().iter())
                .all(|&o| o.is_multiple_of(size) && o + size <= self.limits.page_size);
        if !aligned {
            return false;
        }
        let index = morton(tile.origin[0] / size, tile.origin[1] / size);
        let nodes = self.page(tile.page as usize);
        let covered = (0..tier)
            .any(|level| nodes[level as usize][ancestor(index, tier, level)] == Node::Full);
        if covered || nodes[tier as usize][index] != Node::Free {
            return false;
        }
        nodes[tier as usize][index] = Node::Full;
        for level in (0..tier).rev() {
            let parent = ancestor(index, tier, level);
            let children = &nodes[level as usize + 1][4 * parent..4 * parent + 4];
            nodes[level as usize][parent] = if children.iter().all(|&c| c == Node::Full) {
                Node::Full
            } else {
                Node::Partial
            };
        }
        true
    }

    /// Places a tile of `tier` on the first free square: pages in order, Z-order within a
    /// page. None when no page has one.
    pub fn place(&mut self, tier: u32) -> Option<MapTile> {
        if tier > self.limits.max_tier() {
            return None;
        }
        for page in 0..self.pages.len() {
            if let Some(index) = first_free(self.page(page), 0, 0, tier) {
                let size = self.limits.tile_size(tier);
                let [x, y] = z_order(index as u64);
                let tile = MapTile {
                    origin: UVec2::new(x, y) * size,
                    size,
                    page: page as u32,
                };
                let placed = self.reserve(tile, tier);
                debug_assert!(placed, "a free square is reserved");
                return Some(tile);
            }
        }
        None
    }
}

/// The first free node of `tier` under node `index` of `level`, in Z-order.
fn first_free(nodes: &[Vec<Node>], level: u32, index: usize, tier: u32) -> Option<usize> {
    match nodes[level as usize][index] {
        Node::Full => None,
        Node::Free if level == tier => Some(index),
        Node::Free => Some(index << (2 * (tier - level))),
        Node::Partial if level == tier => None,
        Node::Partial => {
            (4 * index..4 * index + 4).find_map(|c| first_free(nodes, level + 1, c, tier))
        }
    }
}

/// The index of the level-`level` node above node `index` of level `tier`.
fn ancestor(index: usize, tier: u32, level: u32) -> usize {
    index >> (2 * (tier - level))
}

/// The Z-order index of cell (x, y): the inverse of [`z_order`].
fn morton(x: u32, y: u32) -> usize {
    let mut index = 0usize;
    for bit in 0..16 {
        index |= (((x >> bit) & 1) as usize) << (2 * bit);
        index |= (((y >> bit) & 1) as usize) << (2 * bit + 1);
    }
    index
}

/// The cell at `index` along a Z-order (Morton) curve.
pub(crate) fn z_order(index: u64) -> [u32; 2] {
    let (mut x, mut y) = (0u32, 0u32);
    for bit in 0..32 {
        x |= (((index >> (2 * bit)) & 1) as u32) << bit;
        y |= (((index >> (2 * bit + 1)) & 1) as u32) << bit;
    }
    [x, y]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn space(page_size: u32, max_pages: u32) -> AtlasSpace {
        AtlasSpace::new(AtlasLimits {
            page_size,
            max_pages,
        })
    }

    #[test]
    fn morton_inverts_the_z_order() {
        for index in 0..4096 {
            let [x, y] = z_order(index as u64);
            assert_eq!(morton(x, y), index);
        }
    }

    #[test]
    fn tiles_fill_the_free_squares_around_reserved_ones() {
        let mut s = space(1024, 2);
        // A 512² tile kept in the second quadrant of page 0.
        let kept = MapTile {
            origin: UVec2::new(512, 0),
            size: 512,
            page: 0,
        };
        assert!(s.reserve(kept, 1));
        assert!(!s.reserve(kept, 1), "twice");
        let inside = MapTile {
            origin: UVec2::new(768, 256),
            size: 256,
            page: 0,
        };
        assert!(!s.reserve(inside, 2), "inside a kept tile");
        let misaligned = MapTile {
            origin: UVec2::new(128, 0),
            size: 256,
            page: 0,
        };
        assert!(!s.reserve(misaligned, 2));
        // The first free 512² square is the first quadrant, then the third and fourth.
        let placed: Vec<[u32; 2]> = (0..3)
            .map(|_| s.place(1).unwrap().origin.to_array())
            .collect();
        assert_eq!(placed, [[0, 0], [0, 512], [512, 512]]);
        // Page 0 is full: a 256² tile goes to page 1, and a full page fits only there.
        let next = s.place(2).unwrap();
        assert_eq!((next.page, next.origin), (1, UVec2::ZERO));
        assert_eq!(s.place(0), None, "page 1 holds a tile already");
        let mut fresh = space(1024, 2);
        assert!(fresh.reserve(next, 2));
        assert_eq!(fresh.place(0).map(|t| t.page), Some(0));
    }

    #[test]
    fn a_square_whose_quarters_are_full_is_full() {
        let mut s = space(256, 1);
        for _ in 0..4 {
            s.place(1).unwrap();
        }
        assert_eq!(s.place(2), None);
        assert_eq!(s.place(0), None);
    }
}
