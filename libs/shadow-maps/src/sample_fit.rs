//! Where the view's samples are, for maps fitted to them (sample-distribution shadow maps,
//! Lauritzen, Salvi and Lefohn 2010): a compute pass (`shadow-maps/sample_fit.wgsl`) reduces
//! the G-buffer to the nearest and farthest view depth of its surfaces and, for each
//! directional light, the light-space box of the surfaces in each of [`DEPTH_BINS`]
//! logarithmic bins of view depth between the camera's clip planes. The frame waits for its
//! own reduction (a GPU round trip), so every frame's maps fit its own samples.

use std::sync::Arc;

use zoo_host::glam::camera::rh::view::look_to_mat4;
use zoo_host::glam::{Mat4, Vec3};
use zoo_host::gpu::readback::ReadbackRing;
use zoo_host::gpu::{GpuType, gpu_bytes};
use zoo_host::kit::{Stage, StageBindGroup};
use zoo_host::prelude::*;

use crate::light_space::up_for;

/// Logarithmic bins of view depth (`DEPTH_BINS` in the shader).
pub const DEPTH_BINS: usize = 64;
/// Words per bin: the smallest x, y, z, then the largest (`BOX_WORDS` in the shader).
const BOX_WORDS: usize = 6;

zoo_host::gpu_struct! {
    "shadow-maps/fit_params.wgsl" =>
    /// The reduction's uniform (`shadow-maps/sample_fit.wgsl`).
    #[derive(Debug, Clone, Copy)]
    pub struct FitParams {
        /// The camera's near clip plane, where the first bin starts.
        pub near: f32,
        /// The camera's far clip plane, where the last bin ends.
        pub far: f32,
        /// Directional lights with boxes.
        pub lights: u32,
    }
}

/// World to the light space the boxes are in, for a directional light along `direction`
/// (the orientation of its cascades' crops, before their centring).
pub fn fit_view(direction: Vec3) -> Mat4 {
    look_to_mat4(Vec3::ZERO, direction, up_for(direction))
}

/// The float whose order-preserving bits (`ordered` in the shader) are `bits`.
fn from_ordered_bits(bits: u32) -> f32 {
    f32::from_bits(if bits & 0x8000_0000 != 0 {
        bits & 0x7fff_ffff
    } else {
        !bits
    })
}

/// A light-space box: smallest and largest corner.
pub type LightBox = (Vec3, Vec3);

/// One frame's samples: their view-depth range and, per directional light, their boxes by
/// depth bin.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleFit {
    /// Nearest and farthest view depth of the surfaces; `None` when the view shows none.
    pub range: Option<(f32, f32)>,
    /// The view depths the bins span (the camera's clip planes).
    span: (f32, f32),
    /// Per direction of the frame's directional lights (the boxes depend on nothing else), its
    /// bins' boxes.
    boxes: Vec<(Vec3, Vec<Option<LightBox>>)>,
}

impl SampleFit {
    /// The bin of view depth `depth` (`depth_bin` in the shader).
    fn depth_bin(&self, depth: f32) -> usize {
        let (near, far) = self.span;
        let t = (depth / near).ln() / (far / near).ln();
        ((t.max(0.0) * DEPTH_BINS as f32) as usize).min(DEPTH_BINS - 1)
    }

    /// The light-space box ([`fit_view`]) of the samples at view depths `start..=end` for a
    /// directional light along `direction`, from every bin that overlaps them (and one more
    /// each side, for the rounding of bin edges): a box that holds them all; `None` where there
    /// are none or the frame had no such light.
    pub fn samples_box(&self, direction: Vec3, (start, end): (f32, f32)) -> Option<LightBox> {
        let (_, bins) = self.boxes.iter().find(|(d, _)| *d == direction)?;
        let first = self.depth_bin(start).saturating_sub(1);
        let last = (self.depth_bin(end) + 1).min(DEPTH_BINS - 1);
        (bins.get(first..=last)?.iter().flatten())
            .copied()
            .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
    }
}

/// The reduction's stage, buffers and read-back ring.
pub struct SampleReduction {
    stage: Stage,
    params: wgpu::Buffer,
    /// Sized for the frame's lights, with the group over them.
    sized: Option<Sized>,
}

struct Sized {
    lights: usize,
    views: wgpu::Buffer,
    result: wgpu::Buffer,
    group: StageBindGroup,
    ring: ReadbackRing,
    /// The reset values of `result`.
    start: Vec<u32>,
}

impl SampleReduction {
    /// Builds the stage.
    pub fn new(ctx: &RenderContext<'_>) -> TechniqueResult<SampleReduction> {
        let stage = Stage::compute("shadow-maps/sample_fit.wgsl", "cs_sample_fit").build(ctx)?;
        let params = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sample fit parameters"),
            size: FitParams::SIZE as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(SampleReduction {
            stage,
            params,
            sized: None,
        })
    }

    /// Buffers for `lights` directional lights.
    fn sized(&self, ctx: &RenderContext<'_>, lights: usize) -> TechniqueResult<Sized> {
        let device = &ctx.gpu.device;
        let words = DEPTH_BINS * BOX_WORDS;
        let start: Vec<u32> = [u32::MAX, 0]
            .into_iter()
            .chain((0..lights * words).map(|i| if i % BOX_WORDS < 3 { u32::MAX } else { 0 }))
            .collect();
        let buffer = |label, size: usize, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(64) as u64,
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let views = buffer("sample fit light views", 64 * lights, storage);
        let bytes = 4 * start.len();
        let result = buffer(
            "sample fit result",
            bytes,
            storage | wgpu::BufferUsages::COPY_SRC,
        );
        let group = self.stage.bind(
            ctx,
            "sample fit group",
            &[
                ("fit_params", self.params.as_entire_binding()),
                ("fit_views", views.as_entire_binding()),
                ("fit_result", result.as_entire_binding()),
            ],
        )?;
        let ring = ReadbackRing::new(device, "sample fit", bytes as u64, 3);
        Ok(Sized {
            lights,
            views,
            result,
            group,
            ring,
            start,
        })
    }

    /// Records the reduction over the G-buffer and waits for it: this frame's fit (in the
    /// browser build, which cannot wait, the newest fit that has arrived).
    pub fn fit(
        &mut self,
        ctx: &RenderContext<'_>,
        rec: &mut PassRecorder<'_>,
    ) -> TechniqueResult<Arc<SampleFit>> {
        let directions: Vec<Vec3> = (ctx.lights.iter())
            .filter(|l| l.kind == LightKind::Directional)
            .map(|l| l.direction)
            .collect();
        if self
            .sized
            .as_ref()
            .is_none_or(|s| s.lights != directions.len())
        {
            self.sized = Some(self.sized(ctx, directions.len())?);
        }
        let s = self.sized.as_mut().expect("sized above");
        let (gpu, camera) = (ctx.gpu, ctx.camera);
        let params = FitParams {
            near: camera.near,
            far: camera.far,
            lights: directions.len() as u32,
        };
        let views: Vec<Mat4> = directions.iter().map(|&d| fit_view(d)).collect();
        gpu.queue
            .write_buffer(&self.params, 0, &gpu_bytes(&[params]));
        gpu.queue
            .write_buffer(&s.views, 0, bytemuck::cast_slice(&views));
        gpu.queue
            .write_buffer(&s.result, 0, bytemuck::cast_slice(&s.start));
        let extent = [ctx.size.x, ctx.size.y, directions.len().max(1) as u32];
        (self.stage).dispatch(ctx, rec, "Sample fit", &[&s.group], &[], extent)?;
        let bytes = 4 * s.start.len() as u64;
        match s.ring.target() {
            Some(target) => rec
                .encoder()
                .copy_buffer_to_buffer(&s.result, 0, target, 0, bytes),
            // In a browser every readback may still be on its way: this frame's result is
            // not read back.
            None if cfg!(target_arch = "wasm32") => {}
            None => return Err(TechniqueError::not_prepared()),
        }
        let span = (camera.near, camera.far);
        let frame = s.ring.frames();
        // Submitted before the ring maps its targets.
        rec.flush();
        if cfg!(target_arch = "wasm32") {
            // A browser cannot wait for the GPU within a frame: the newest fit that has
            // arrived (a frame or two old; none, the whole view, before the first).
            let fit = match s.ring.latest(&gpu.device) {
                Some((_, data)) => decode(bytemuck::cast_slice(data), span, &directions),
                None => decode(&s.start, span, &directions),
            };
            return Ok(Arc::new(fit));
        }
        // The ring maps what arrived at one poll and returns it at the next.
        for _ in 0..3 {
            gpu.wait_idle();
            if let Some((arrived, data)) = s.ring.latest(&gpu.device)
                && arrived == frame
            {
                let words: &[u32] = bytemuck::cast_slice(data);
                return Ok(Arc::new(decode(words, span, &directions)));
            }
        }
        Err(TechniqueError::Other(
            "sample fit: the reduction's results did not arrive".into(),
        ))
    }
}

/// The fit in read-back `words` over bins spanning `span`, with boxes for directional lights
/// along `directions`, in order.
fn decode(words: &[u32], span: (f32, f32), directions: &[Vec3]) -> SampleFit {
    // Without surfaces the depths stay (u32::MAX, 0).
    let (near, far) = (f32::from_bits(words[0]), f32::from_bits(words[1]));
    let range = (far > 0.0).then(|| (near, far.max(near * 1.001)));
    let mut boxes = Vec::new();
    for (slot, &direction) in directions.iter().enumerate() {
        let light_words = &words[2 + slot * DEPTH_BINS * BOX_WORDS..][..DEPTH_BINS * BOX_WORDS];
        let bins = (light_words.chunks_exact(BOX_WORDS))
            .map(|w| {
                let corner =
                    |w: &[u32]| Vec3::from_array([0, 1, 2].map(|k| from_ordered_bits(w[k])));
                (w[0] != u32::MAX).then(|| (corner(&w[..3]), corner(&w[3..])))
            })
            .collect();
        boxes.push((direction, bins));
    }
    SampleFit { range, span, boxes }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bits of `x` that order as the floats do (`ordered` in the shader).
    fn ordered_bits(x: f32) -> u32 {
        let bits = x.to_bits();
        if bits & 0x8000_0000 != 0 {
            !bits
        } else {
            bits | 0x8000_0000
        }
    }

    #[test]
    fn ordered_bits_order_as_the_floats_and_come_back() {
        let values = [-1e30, -2.5, -1e-20, -0.0, 0.0, 1e-20, 3.0, 7e25];
        for pair in values.windows(2) {
            assert!(ordered_bits(pair[0]) <= ordered_bits(pair[1]), "{pair:?}");
        }
        for v in values {
            assert_eq!(from_ordered_bits(ordered_bits(v)).to_bits(), v.to_bits());
        }
    }

    #[test]
    fn a_split_s_box_holds_every_bin_it_overlaps() {
        let bin_box = |k: usize| {
            let x = k as f32;
            Some((Vec3::new(x, -x, 0.0), Vec3::new(x + 1.0, 1.0 - x, 1.0)))
        };
        let mut bins = vec![None; DEPTH_BINS];
        for k in [10, 20, 30] {
            bins[k] = bin_box(k);
        }
        let fit = SampleFit {
            range: Some((1.0, 100.0)),
            span: (0.1, 1000.0),
            boxes: vec![(Vec3::NEG_Y, bins)],
        };
        // The bin edges: 0.1 * 10^(4 k / 64).
        let edge = |k: f32| 0.1 * 10f32.powf(4.0 * k / DEPTH_BINS as f32);
        let whole = fit
            .samples_box(Vec3::NEG_Y, (edge(10.5), edge(20.5)))
            .unwrap();
        assert_eq!(
            whole,
            (Vec3::new(10.0, -20.0, 0.0), Vec3::new(21.0, -9.0, 1.0))
        );
        assert_eq!(fit.samples_box(Vec3::NEG_Y, (edge(23.0), edge(27.0))), None);
        assert_eq!(
            fit.samples_box(Vec3::X, (0.1, 1000.0)),
            None,
            "no light along that direction"
        );
        assert_eq!(fit.depth_bin(0.01), 0);
        assert_eq!(fit.depth_bin(1e6), DEPTH_BINS - 1);
    }

    #[test]
    fn shared_numbers_match_the_shader() {
        let source = zoo_host::ShaderLibrary::embedded()
            .compose("shadow-maps/sample_fit.wgsl")
            .unwrap()
            .source;
        let constant = |name| zoo_host::gpu::layout::wgsl_integer_constant(&source, name);
        assert_eq!(constant("DEPTH_BINS"), Ok(DEPTH_BINS as i64));
        assert_eq!(constant("BOX_WORDS"), Ok(BOX_WORDS as i64));
    }
}
