//! One layer's tile to render in a frame ([`TilePass`]) and the name of its pass.

use zoo_host::gpu::{PassRecorder, RecordedRenderPass};
use zoo_host::wgpu;

use crate::atlas_pages::MapTile;
use crate::planning::LightMaps;

/// The name of the pass that renders `layer` of a light's layers: `"{base}: light {l}"` for
/// a light with one layer, else `"{base}: light {l} {word} {layer}"` with the plan's word for
/// its layers ("face" for cube faces, "split" for cascades).
pub fn layer_pass_name(base: &str, maps: &LightMaps, layer: usize) -> String {
    let light = maps.light;
    match maps.frustums.len() {
        1 => format!("{base}: light {light}"),
        _ => format!("{base}: light {light} {} {layer}", maps.layer_word),
    }
}

/// One layer's map to render: its light, the layer within the light, its index among all
/// layers (and layer cameras) and its tile.
#[derive(Debug, Clone, Copy)]
pub struct TilePass<'a> {
    pub maps: &'a LightMaps,
    pub face: usize,
    pub layer: u32,
    pub tile: MapTile,
    /// The first tile rendered on its page this frame: its pass clears the page.
    pub first_on_page: bool,
}

impl TilePass<'_> {
    /// The pass's name: [`layer_pass_name`] with `base`.
    pub fn name(&self, base: &str) -> String {
        layer_pass_name(base, self.maps, self.face)
    }

    /// Opens the tile's render pass, named by [`Self::name`] with `base`, on `colors` and the
    /// depth page `depth` (loaded by `depth_load`, stored), restricted to the tile.
    pub fn begin<'r>(
        &self,
        recorder: &'r mut PassRecorder<'_>,
        base: &str,
        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth: &wgpu::TextureView,
        depth_load: wgpu::LoadOp<f32>,
    ) -> RecordedRenderPass<'r> {
        let mut pass = recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some(&self.name(base)),
            color_attachments: colors,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: depth_load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.tile.restrict(&mut pass);
        pass
    }

    /// Clear on the page's first pass, else keep what the page's other tiles hold.
    pub fn load_op<V>(&self, clear: V) -> wgpu::LoadOp<V> {
        match self.first_on_page {
            true => wgpu::LoadOp::Clear(clear),
            false => wgpu::LoadOp::Load,
        }
    }
}
