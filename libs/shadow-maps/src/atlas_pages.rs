//! The shadow atlas's pages and tiles: how many pages of what size the device and the memory
//! budget allow ([`AtlasLimits`]) and where a layer's map lies on them ([`MapTile`]).

use zoo_host::glam::UVec2;
use zoo_host::wgpu;

/// Shadow maps are kept under this many bytes (the atlas pages, with their depth scratch).
pub const MEMORY_BUDGET: u64 = 1 << 30;
/// The texel budget: at most this many pages, each the size of one full-tier map (so the
/// requested map size scales the budget: 64 maps of 2048² are 1 GiB of depth).
pub const MAX_PAGES: u32 = 64;
/// The smallest tile side, in texels.
pub const MIN_TILE: u32 = 16;
/// Tiles are multiples of this many texels per side (min-filtered maps read blocks of it).
pub const TILE_ALIGN: u32 = 8;

zoo_host::gpu_struct! {
    "shadow-maps/map_tile.wgsl" =>
    /// Where one layer's map lies in the atlas (`shadow-maps/layers.wgsl` reads it).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
    pub struct MapTile {
        /// Texel of the page the tile starts at.
        pub origin: UVec2,
        /// Texels per side.
        pub size: u32,
        /// Array layer of the atlas.
        pub page: u32,
    }
}

impl MapTile {
    /// Restricts a render pass to the tile.
    pub fn restrict(&self, pass: &mut wgpu::RenderPass<'_>) {
        let UVec2 { x, y } = self.origin;
        let size = self.size as f32;
        pass.set_viewport(x as f32, y as f32, size, size, 0.0, 1.0);
        pass.set_scissor_rect(x, y, self.size, self.size);
    }
}

/// What the atlas may use: square pages of `page_size` texels, at most `max_pages` of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtlasLimits {
    pub page_size: u32,
    pub max_pages: u32,
}

impl AtlasLimits {
    /// Pages of the requested map size, at most [`MAX_PAGES`] of them, within the device's
    /// texture size and array layers and [`MEMORY_BUDGET`] for maps of `bytes_per_texel` (plus `scratch_pages` single pages
    /// of `scratch_bytes` per texel that go with them, such as a depth scratch). Says why when
    /// the page is smaller than requested.
    pub fn new(
        requested: u32,
        limits: &wgpu::Limits,
        spare_layer: bool,
        bytes_per_texel: u64,
        scratch_bytes: u64,
    ) -> (AtlasLimits, Option<String>) {
        let mut page_size = requested.min(limits.max_texture_dimension_2d).max(MIN_TILE);
        let mut note = (page_size < requested)
            .then(|| format!("map_size {requested} exceeds the device limit; using {page_size}"));
        let layers = limits
            .max_texture_array_layers
            .saturating_sub(u32::from(spare_layer))
            .clamp(1, MAX_PAGES);
        let max_pages = |page: u32| {
            let texels = u64::from(page).pow(2);
            let room = MEMORY_BUDGET.saturating_sub(texels * scratch_bytes);
            (room / (texels * bytes_per_texel)).min(u64::from(layers)) as u32
        };
        while max_pages(page_size) == 0 && page_size > MIN_TILE {
            page_size /= 2;
            note = Some(format!(
                "one {requested}² map exceeds {} MiB; using {page_size}",
                MEMORY_BUDGET >> 20
            ));
        }
        let limits = AtlasLimits {
            page_size,
            max_pages: max_pages(page_size).max(1),
        };
        (limits, note)
    }

    /// The largest tier: tiles of `page_size >> max_tier` are at least [`MIN_TILE`] texels and
    /// a multiple of [`TILE_ALIGN`].
    pub fn max_tier(&self) -> u32 {
        let aligned = self
            .page_size
            .trailing_zeros()
            .saturating_sub(TILE_ALIGN.ilog2());
        let sized = (self.page_size / MIN_TILE).max(1).ilog2();
        aligned.min(sized)
    }

    /// Texels per side of a tile of `tier`.
    pub fn tile_size(&self, tier: u32) -> u32 {
        self.page_size >> tier
    }
}
