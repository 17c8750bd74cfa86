//! Sample-distribution shadow maps (`sdsm`; Lauritzen, Salvi and Lefohn 2010): pssm's splits,
//! crops, lookup and blending over the view depths the pixels really hold. A compute pass
//! (`pssm/sdsm.wgsl`) reduces the G-buffer to its nearest and farthest surface depth (sky
//! excluded) and copies them back to the CPU, where the cascades are planned over them. One
//! frame of latency: a frame splits over the newest range that has arrived (the previous
//! frame's), and waits for its own only when there is none (first frame, new scene or size), so
//! a single frame is exact; a view without surfaces keeps pssm's range (the objects' boxes).

use zoo_host::gpu::readback::{ReadbackRing, f32s};
use zoo_host::kit::{Stage, StageBindGroup};
use zoo_host::prelude::*;
use zoo_host::technique::{DebugImage, ResourceInfo};

use crate::{Pssm, PssmParams};

/// The reduction's pipeline, its bind group over `range` (the depths' f32 bits), and the ring
/// reading `range` back a frame late.
struct Reduction {
    stage: Stage,
    group: StageBindGroup,
    range: wgpu::Buffer,
    ring: ReadbackRing,
}

impl Reduction {
    fn new(ctx: &RenderContext<'_>) -> TechniqueResult<Reduction> {
        let stage = Stage::compute("pssm/sdsm.wgsl", "cs_depth_range").build(ctx)?;
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let range = ctx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sdsm depth range"),
            size: 8,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let entry = ("depth_range", range.as_entire_binding());
        let group = stage.bind(ctx, "sdsm depth range group", &[entry])?;
        let ring = ReadbackRing::new(&ctx.gpu.device, "sdsm depth range", 8, 3);
        Ok(Reduction {
            stage,
            group,
            range,
            ring,
        })
    }

    /// Records the reduction; returns the newest range (this frame's when none has arrived),
    /// `None` for a view without surfaces.
    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        rec: &mut PassRecorder<'_>,
    ) -> TechniqueResult<Option<(f32, f32)>> {
        let (gpu, extent) = (ctx.gpu, [ctx.size.x, ctx.size.y, 1]);
        let mut latest = self.ring.latest(&gpu.device).map(|(_, b)| f32s(b));
        // Nearest from the largest bits down, farthest from 0 up.
        let start: &[u32] = &[u32::MAX, 0];
        gpu.queue
            .write_buffer(&self.range, 0, bytemuck::cast_slice(start));
        (self.stage).dispatch(ctx, rec, "SDSM depth range", &[&self.group], &[], extent)?;
        if let Some(target) = self.ring.target() {
            rec.encoder()
                .copy_buffer_to_buffer(&self.range, 0, target, 0, 8);
        }
        for _ in 0..2 {
            if latest.is_none() {
                // Submit the G-buffer and the reduction, and wait for this frame's range.
                rec.flush();
                gpu.wait_idle();
                latest = self.ring.latest(&gpu.device).map(|(_, b)| f32s(b));
            }
        }
        // Without surfaces the bits stay (u32::MAX, 0): NaN and 0.
        let range = latest.filter(|d| d[1] > 0.0);
        Ok(range.map(|d| (d[0], d[1].max(d[0] * 1.001))))
    }
}

struct Sdsm {
    pssm: Pssm,
    reduction: Option<Reduction>,
}

impl ShadowTechnique for Sdsm {
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> TechniqueResult {
        if changes.scene || changes.resolution || self.reduction.is_none() {
            // A new ring: the first frame waits for its range.
            self.reduction = Some(Reduction::new(ctx)?);
        }
        self.pssm.prepare(ctx, changes)
    }

    fn record(&mut self, ctx: &RenderContext<'_>, rec: &mut PassRecorder<'_>) -> TechniqueResult {
        let reduction = (self.reduction.as_mut()).ok_or_else(TechniqueError::not_prepared)?;
        let range = reduction.record(ctx, rec)?;
        if range != self.pssm.range {
            self.pssm.range = range;
            let moved = Changes {
                camera: true,
                ..Changes::default()
            };
            self.pssm.prepare(ctx, moved)?;
        }
        self.pssm.record(ctx, rec)
    }

    /// pssm's, and the range the splits cover.
    fn counters(&self) -> Vec<(String, f64)> {
        let mut out = self.pssm.counters();
        if let Some((near, far)) = self.pssm.range {
            out.push(("sdsm near".into(), near.into()));
            out.push(("sdsm far".into(), far.into()));
        }
        out
    }

    fn resources(&self) -> Vec<ResourceInfo> {
        self.pssm.resources()
    }

    fn update_params(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        self.pssm.update_params(values)
    }

    fn debug_view(&self, resource: &str) -> Option<DebugImage<'_>> {
        self.pssm.debug_view(resource)
    }
}

fn create(_: &GpuContext, values: &ParamValues) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let pssm = Pssm::new(values)?;
    Ok(Box::new(Sdsm {
        pssm,
        reduction: None,
    }))
}

zoo_host::register_technique! {
    id: "sdsm",
    name: "Sample-distribution shadow maps",
    description: "Directional lights: pssm's splits over the nearest and farthest view depth of the depth buffer's surfaces, reduced on the GPU",
    source: "Lauritzen, Salvi and Lefohn 2010 (sample distribution shadow maps)",
    readme: include_str!("../README.md"),
    light_kinds: &[LightKind::Directional],
    params: PssmParams::schema,
    required_downlevel: || wgpu::DownlevelFlags::COMPUTE_SHADERS,
    create: create,
}
