//! One frame: G-buffer, visibility clear, the technique's passes, then lighting or a debug view.

use std::sync::Arc;

use glam::UVec2;

mod containment;
mod debug_source;
mod readout;
mod view;

use containment::{ActiveTechnique, guarded, instantiate};
pub use readout::{GBufferData, PendingReadout, Readout, ReadoutRequest};
pub use view::{Overlay, View};

use super::debug_view::DebugViewPass;
use super::frame::FrameBindings;
use super::gbuffer::{GBuffer, GBufferPass};
use super::lighting::{LightingPass, OUTPUT_FORMAT};
use super::scene_buffers::SceneBuffers;
use super::visibility::{
    INDIRECT_FORMAT, IndirectTarget, SlotAssignment, SlotRequest, TransmittanceTargets,
    VISIBILITY_FORMAT, VisibilityTargets,
};
use crate::gpu::{
    FrameTimings, GpuContext, PassOwner, PassRecorder, ShaderError, ShaderLibrary,
    StatisticsQueries, TimestampQueries,
};
use crate::params::{self, ParamValues};
use crate::scene::{Camera, Light, Scene};
use crate::technique::{
    self, Changes, ParamUpdate, RenderContext, ShadowTechnique, TechniqueError,
    TechniqueRegistration,
};

/// Errors creating the renderer.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("invalid output size {0}x{1}: both sides must be 1..={2}")]
    Size(u32, u32, u32),
    #[error(transparent)]
    Shader(#[from] ShaderError),
    #[error(transparent)]
    Technique(#[from] TechniqueError),
    #[error("view `{0}`: {1}")]
    View(String, String),
}

/// Renders scenes with one technique at a time.
pub struct Renderer {
    gpu: Arc<GpuContext>,
    shaders: ShaderLibrary,
    scene: Scene,
    camera: Camera,
    lights: Vec<Light>,
    size: UVec2,
    scene_buffers: SceneBuffers,
    frame: FrameBindings,
    gbuffer: GBuffer,
    visibility: VisibilityTargets,
    transmittance: TransmittanceTargets,
    indirect: IndirectTarget,
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    gbuffer_pass: GBufferPass,
    lighting: LightingPass,
    lighting_inputs: wgpu::BindGroup,
    debug: DebugViewPass,
    timestamps: Option<TimestampQueries>,
    statistics: Option<StatisticsQueries>,
    technique: ActiveTechnique,
    /// Why the technique's last slot assignment was refused, until the next frame reports it.
    slot_error: Option<TechniqueError>,
    /// Whether techniques may keep work whose inputs did not change (see
    /// [`RenderContext::reuse_unchanged`]).
    reuse_unchanged: bool,
}

fn create_output(gpu: &GpuContext, size: UVec2) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("output image"),
        size: wgpu::Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: OUTPUT_FORMAT,
        usage: super::lighting::OUTPUT_USAGE,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some("output image view"),
        ..Default::default()
    });
    (texture, view)
}

/// Borrows the renderer's fields (not the technique) as a [`RenderContext`].
macro_rules! render_context {
    ($renderer:ident, $resource:expr) => {
        RenderContext {
            gpu: &$renderer.gpu,
            shaders: &$renderer.shaders,
            scene: &$renderer.scene,
            scene_buffers: &$renderer.scene_buffers,
            frame: &$renderer.frame,
            gbuffer: &$renderer.gbuffer,
            visibility: &$renderer.visibility,
            transmittance: &$renderer.transmittance,
            indirect: &$renderer.indirect,
            camera: &$renderer.camera,
            lights: &$renderer.lights,
            size: $renderer.size,
            debug_view: $resource,
            reuse_unchanged: $renderer.reuse_unchanged,
        }
    };
}

/// The technique resource a frame shows: the debug view's, or the overlay's over the final
/// image (the technique's `debug_view`).
fn shown_resource<'a>(view: &'a View, overlay: Option<&'a Overlay>) -> Option<&'a str> {
    match (view, overlay) {
        (View::Resource(name), _) => Some(name.as_str()),
        (
            _,
            Some(Overlay {
                view: View::Resource(name),
                ..
            }),
        ) => Some(name.as_str()),
        _ => None,
    }
}

/// Largest accepted output side.
pub const MAX_OUTPUT_SIDE: u32 = 8192;

impl Renderer {
    /// Creates a renderer for `scene` at `size`, starting with the `unshadowed` technique.
    pub fn new(gpu: Arc<GpuContext>, scene: Scene, size: UVec2) -> Result<Renderer, RenderError> {
        Self::with_shaders(gpu, scene, size, ShaderLibrary::embedded())
    }

    /// As [`Renderer::new`] with a given shader library (the viewer reads shaders from disk).
    pub fn with_shaders(
        gpu: Arc<GpuContext>,
        scene: Scene,
        size: UVec2,
        shaders: ShaderLibrary,
    ) -> Result<Renderer, RenderError> {
        check_size(size)?;
        let baseline = technique::find_technique(crate::builtin::UNSHADOWED_ID)?;
        let technique = instantiate(&gpu, baseline, &ParamValues::new())?;
        let scene_buffers = SceneBuffers::new(&gpu, &scene);
        let frame = FrameBindings::new(&gpu, &scene);
        let gbuffer = GBuffer::new(&gpu, size);
        let slots = SlotAssignment::one_per_light(scene.lights.len());
        let transmittance = TransmittanceTargets::new(&gpu, size, &slots, false);
        let visibility = VisibilityTargets::new(&gpu, size, slots);
        let indirect = IndirectTarget::new(&gpu, size);
        let (output, output_view) = create_output(&gpu, size);
        let gbuffer_pass = GBufferPass::new(&gpu, &shaders, &frame, &scene_buffers.materials)?;
        let lighting = LightingPass::new(&gpu, &shaders, &frame, &gbuffer)?;
        let lighting_inputs = lighting.inputs(&gpu, &visibility, &indirect, &transmittance);
        let debug = DebugViewPass::new(&gpu, &shaders)?;
        let timestamps = TimestampQueries::new(&gpu);
        let mut renderer = Renderer {
            camera: scene.camera,
            lights: scene.lights.clone(),
            gpu,
            shaders,
            scene,
            size,
            scene_buffers,
            frame,
            gbuffer,
            visibility,
            transmittance,
            indirect,
            output,
            output_view,
            gbuffer_pass,
            lighting,
            lighting_inputs,
            debug,
            timestamps,
            statistics: None,
            technique,
            slot_error: None,
            reuse_unchanged: true,
        };
        renderer.update_slots();
        Ok(renderer)
    }

    /// The GPU context.
    pub fn gpu(&self) -> &Arc<GpuContext> {
        &self.gpu
    }

    /// The shader library its pipelines are built from.
    pub fn shaders(&self) -> &ShaderLibrary {
        &self.shaders
    }

    /// The scene being rendered.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Output size.
    pub fn size(&self) -> UVec2 {
        self.size
    }

    /// The current lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The current camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The constant ambient light the lighting pass adds: the scene's, which stands in for
    /// indirect light, or none while the technique adds indirect light itself.
    pub fn ambient(&self) -> glam::Vec3 {
        if self.technique.registration.adds_light {
            glam::Vec3::ZERO
        } else {
            self.scene.ambient
        }
    }

    /// The active technique's registration.
    pub fn technique(&self) -> &'static TechniqueRegistration {
        self.technique.registration
    }

    /// The active technique instance (resources, counters, passes).
    pub fn technique_instance(&self) -> &dyn ShadowTechnique {
        self.technique.instance.as_ref()
    }

    /// The technique's counters for the last frame rendered, waiting for the GPU until they
    /// have arrived (counters are read back without stalling frames, so
    /// `technique_instance().counters()` lags a frame or two). For tools and tests, not for
    /// interactive frames.
    pub fn wait_for_counters(&self) -> Vec<(String, f64)> {
        let mut counters = Vec::new();
        for _ in 0..4 {
            self.gpu.wait_idle();
            counters = self.technique.instance.counters();
            if !counters.is_empty() {
                break;
            }
        }
        counters
    }

    /// The active technique's parameter values.
    pub fn technique_params(&self) -> &ParamValues {
        &self.technique.params
    }

    /// The visibility slots in use.
    pub fn slots(&self) -> &SlotAssignment {
        &self.visibility.slots
    }

    /// The visibility storage (slot views and their channel selectors).
    pub fn visibility(&self) -> &VisibilityTargets {
        &self.visibility
    }

    /// Switches to technique `id` with `values` (missing keys take defaults). On error the
    /// current technique stays active. The old technique's resources are dropped.
    pub fn set_technique(&mut self, id: &str, values: &ParamValues) -> Result<(), TechniqueError> {
        let registration = technique::find_technique(id)?;
        let next = instantiate(&self.gpu, registration, values)?;
        // Refused slots keep the current technique, as any other failure to switch does.
        let slots = self.slots_of(&next)?;
        self.technique = next;
        self.apply_slots(slots);
        Ok(())
    }

    /// Changes the current technique's parameters: applied to the live instance when it can
    /// take them ([`ShadowTechnique::update_params`]), else a new instance is created. Returns
    /// whether they were applied in place. On error the technique and its values stay.
    pub fn set_params(&mut self, values: &ParamValues) -> Result<bool, TechniqueError> {
        let registration = self.technique.registration;
        let schema = (registration.params)();
        let mut params = params::defaults(&schema);
        for (key, value) in values {
            params::find_spec(&schema, key)?.check(value)?;
            params.insert(key.clone(), value.clone());
        }
        let instance = &mut self.technique.instance;
        let update = guarded(&self.gpu, registration.id, || {
            instance.update_params(&params)
        })?;
        match update {
            ParamUpdate::Applied => {
                self.technique.params = params;
                self.technique.pending.params = true;
                Ok(true)
            }
            ParamUpdate::Rebuild => {
                self.set_technique(registration.id, &params)?;
                Ok(false)
            }
        }
    }

    /// Counts vertex, fragment and compute invocations per pass (where the device has
    /// pipeline-statistics queries). Returns whether counting is on.
    pub fn set_pipeline_statistics(&mut self, enabled: bool) -> bool {
        self.statistics = if enabled {
            StatisticsQueries::new(&self.gpu)
        } else {
            None
        };
        self.statistics.is_some()
    }

    /// Times passes on the CPU clock, each submitted on its own and waited for, instead of
    /// with GPU timestamps (when `enabled`; timestamps are used again where the device has
    /// them otherwise). CPU drivers such as lavapipe run compute dispatches outside the span
    /// their timestamps measure.
    pub fn set_cpu_timing(&mut self, enabled: bool) {
        self.timestamps = if enabled {
            None
        } else {
            TimestampQueries::new(&self.gpu)
        };
    }

    /// Changes the output size.
    pub fn set_size(&mut self, size: UVec2) -> Result<(), RenderError> {
        check_size(size)?;
        if size != self.size {
            self.size = size;
            self.gbuffer = GBuffer::new(&self.gpu, size);
            self.indirect = IndirectTarget::new(&self.gpu, size);
            (self.output, self.output_view) = create_output(&self.gpu, size);
            self.visibility =
                VisibilityTargets::new(&self.gpu, size, self.visibility.slots.clone());
            self.update_transmittance(true);
            self.technique.pending.resolution = true;
            // The aspect ratio is part of what slots are assigned for.
            self.update_slots();
        }
        Ok(())
    }

    /// Whether techniques may keep work from earlier frames whose inputs did not change (shadow
    /// maps of lights that did not move, for example): on by default; off, every frame does
    /// all of its work, as when measuring a technique's full cost per frame.
    pub fn set_reuse_unchanged(&mut self, reuse: bool) {
        self.reuse_unchanged = reuse;
    }

    /// Whether techniques may keep unchanged work ([`Self::set_reuse_unchanged`]).
    pub fn reuse_unchanged(&self) -> bool {
        self.reuse_unchanged
    }

    /// Moves the camera.
    pub fn set_camera(&mut self, camera: Camera) {
        if camera != self.camera {
            self.camera = camera;
            self.technique.pending.camera = true;
            if self.technique.instance.slots_follow_camera() {
                self.update_slots();
            }
        }
    }

    /// Replaces the lights (same count as the scene's, at most).
    pub fn set_lights(&mut self, lights: Vec<Light>) {
        if lights != self.lights {
            let count_changed = lights.len() != self.lights.len();
            self.lights = lights;
            if count_changed {
                self.frame.set_light_capacity(&self.gpu, self.lights.len());
            }
            self.update_slots();
            self.technique.pending.lights = true;
        }
    }

    /// The slots `technique` assigns for the current lights, camera and size, checked against
    /// the light count and the device's array-layer limit.
    fn slots_of(&self, technique: &ActiveTechnique) -> Result<SlotAssignment, TechniqueError> {
        let request = SlotRequest {
            lights: &self.lights,
            camera: &self.camera,
            aspect: self.size.x as f32 / self.size.y as f32,
        };
        let id = technique.registration.id;
        let instance = &technique.instance;
        let slots = guarded(&self.gpu, id, || instance.assign_slots(&request))?;
        if slots.len() != self.lights.len() {
            return Err(TechniqueError::Other(format!(
                "{id}: assigned visibility slots to {} lights, the scene has {}",
                slots.len(),
                self.lights.len()
            )));
        }
        // Four visibility slots share an array layer; transmittance takes a layer per slot.
        let max_layers = self.gpu.device.limits().max_texture_array_layers;
        let transmittance = instance.writes_transmittance(&self.scene);
        let layers = match transmittance {
            true => slots.slot_count(),
            false => slots.layer_count(),
        };
        if layers > max_layers {
            let what = if transmittance {
                " with transmittance"
            } else {
                ""
            };
            return Err(TechniqueError::Other(format!(
                "{id}: {} visibility slots{what} need {layers} texture array layers, more than the device's {max_layers}",
                slots.slot_count()
            )));
        }
        Ok(slots)
    }

    /// Asks the technique for its slot assignment and applies it. A refusal is kept and
    /// reported by the next [`Self::render`]; meanwhile every light has a slot of its own, so
    /// the storage always matches the lights.
    fn update_slots(&mut self) {
        match self.slots_of(&self.technique) {
            Ok(slots) => {
                self.slot_error = None;
                self.apply_slots(slots);
            }
            Err(e) => {
                self.slot_error = Some(e);
                self.apply_slots(SlotAssignment::one_per_light(self.lights.len()));
            }
        }
    }

    /// Uses `slots`: the storage is kept when it has as many layers (lights only change
    /// channels), else rebuilt; the technique hears of any change.
    fn apply_slots(&mut self, slots: SlotAssignment) {
        if slots == self.visibility.slots {
            self.update_transmittance(false);
            return;
        }
        let same_storage = slots.layer_count() == self.visibility.slots.layer_count();
        if same_storage {
            self.visibility.slots = slots;
        } else {
            self.visibility = VisibilityTargets::new(&self.gpu, self.size, slots);
        }
        self.technique.pending.lights = true;
        self.update_transmittance(!same_storage);
    }

    /// Fits the transmittance storage to the technique, the slots and the size, and rebuilds
    /// the lighting inputs when it or the visibility storage (`visibility_changed`) changed.
    fn update_transmittance(&mut self, visibility_changed: bool) {
        let in_use = self.technique.instance.writes_transmittance(&self.scene);
        let slots = &self.visibility.slots;
        let fits = self.transmittance.fits(self.size, slots, in_use);
        if !fits {
            self.transmittance = TransmittanceTargets::new(&self.gpu, self.size, slots, in_use);
        }
        if !fits || visibility_changed {
            self.lighting_inputs = self.lighting.inputs(
                &self.gpu,
                &self.visibility,
                &self.indirect,
                &self.transmittance,
            );
        }
    }

    /// Renders one frame into the output image and returns its pass timings. If the technique
    /// fails (error, panic or GPU validation error) it is replaced by `unshadowed` and the error
    /// is returned; the next frame renders normally.
    pub fn render(&mut self, view: &View) -> Result<FrameTimings, RenderError> {
        self.render_with_overlay(view, None)
    }

    /// As [`Renderer::render`], blending `overlay` (a debug view) over the final image.
    pub fn render_with_overlay(
        &mut self,
        view: &View,
        overlay: Option<&Overlay>,
    ) -> Result<FrameTimings, RenderError> {
        if let Some(error) = self.slot_error.take() {
            return Err(self.fallback_later(error));
        }
        let overlay = overlay.filter(|o| *view == View::Final && o.view != View::Final);
        let resource = shown_resource(view, overlay);
        self.frame.update(
            &self.gpu,
            &self.camera,
            self.ambient(),
            &self.lights,
            &self.visibility.slots,
            self.size,
        );
        self.prepare_pending(resource)?;

        // Views are checked before recording, so a bad one never leaves a recorded frame
        // unsubmitted (readbacks the technique set up for it would never arrive).
        if *view != View::Final {
            self.debug_source(view)?;
        }
        if let Some(overlay) = overlay {
            self.debug_source(&overlay.view)?;
        }
        let id = self.technique.registration.id;
        let ctx = render_context!(self, resource);
        let mut recorder = PassRecorder::new(&self.gpu, self.timestamps.as_ref())
            .with_statistics(self.statistics.as_ref());
        self.record_technique_inputs(&mut recorder);
        recorder.set_owner(PassOwner::Technique);
        let active = &mut self.technique;
        let recorded = guarded(&self.gpu, id, || {
            active.instance.record(&ctx, &mut recorder)
        });
        if let Err(e) = recorded {
            drop(recorder);
            self.gpu.wait_idle();
            return Err(self.fallback_later(e));
        }
        recorder.set_owner(PassOwner::Host);
        self.record_output(&mut recorder, view, overlay)?;
        let timings = recorder.finish();
        let errors = self.gpu.take_uncaptured_errors();
        if !errors.is_empty() {
            return Err(self.fallback_later(TechniqueError::Validation {
                id: id.to_string(),
                message: errors.join("; "),
            }));
        }
        Ok(timings)
    }

    /// Prepares the technique for the changes made since its last preparation, if any.
    fn prepare_pending(&mut self, resource: Option<&str>) -> Result<(), RenderError> {
        if self.technique.pending == Changes::default() {
            return Ok(());
        }
        let id = self.technique.registration.id;
        let changes = self.technique.pending;
        let ctx = render_context!(self, resource);
        let active = &mut self.technique;
        let prepared = guarded(&self.gpu, id, || active.instance.prepare(&ctx, changes));
        if let Err(e) = prepared {
            return Err(self.fallback_later(e));
        }
        self.technique.pending = Changes::default();
        Ok(())
    }

    /// Records what the technique reads and writes: the G-buffer pass, and the visibility,
    /// transmittance and indirect targets cleared.
    fn record_technique_inputs(&self, recorder: &mut PassRecorder<'_>) {
        self.gbuffer_pass.record(
            recorder,
            &self.gbuffer,
            &self.frame,
            &self.scene,
            &self.scene_buffers,
        );
        clear_visibility(
            recorder,
            &self.gpu.device.limits(),
            &self.visibility,
            &self.transmittance,
            &self.indirect,
        );
    }

    /// Records the output image: the lit final image or a debug view, then the overlay
    /// blended over it.
    fn record_output(
        &self,
        recorder: &mut PassRecorder<'_>,
        view: &View,
        overlay: Option<&Overlay>,
    ) -> Result<(), RenderError> {
        match view {
            View::Final => self.lighting.record(
                recorder,
                &self.output_view,
                &self.frame,
                &self.gbuffer,
                &self.lighting_inputs,
            ),
            other => {
                let source = self.debug_source(other)?;
                self.debug
                    .record(&self.gpu, recorder, &self.output_view, &source, None);
            }
        }
        if let Some(overlay) = overlay {
            let source = self.debug_source(&overlay.view)?;
            self.debug.record(
                &self.gpu,
                recorder,
                &self.output_view,
                &source,
                Some(overlay.opacity),
            );
        }
        Ok(())
    }

    /// Re-reads the shader library (after files under `shaders/` changed) and rebuilds the host
    /// pipelines and the technique's. Every shader is validated first and the technique is
    /// prepared before anything is swapped, so on error (returned with file, line and column)
    /// the previous pipelines keep running.
    pub fn reload_shaders(&mut self) -> Result<(), RenderError> {
        for name in self.shaders.file_names() {
            // Shared modules are checked through the shaders that import them; shaders of
            // plugins this build does not link cannot be composed and are not used.
            let unused = self.shaders.needs_unlinked_module(&name);
            if !self.shaders.is_shared_module(&name) && !unused {
                self.shaders.validate(&name)?;
            }
        }
        let gbuffer_pass = GBufferPass::new(
            &self.gpu,
            &self.shaders,
            &self.frame,
            &self.scene_buffers.materials,
        )?;
        let lighting = LightingPass::new(&self.gpu, &self.shaders, &self.frame, &self.gbuffer)?;
        let debug = DebugViewPass::new(&self.gpu, &self.shaders)?;
        let registration = self.technique.registration;
        let mut next = instantiate(&self.gpu, registration, &self.technique.params)?;
        let ctx = render_context!(self, None);
        guarded(&self.gpu, registration.id, || {
            next.instance.prepare(&ctx, Changes::ALL)
        })?;
        next.pending = Changes::default();
        self.lighting_inputs = lighting.inputs(
            &self.gpu,
            &self.visibility,
            &self.indirect,
            &self.transmittance,
        );
        self.gbuffer_pass = gbuffer_pass;
        self.lighting = lighting;
        self.debug = debug;
        self.technique = next;
        Ok(())
    }

    /// Swaps in `unshadowed` after a failure and passes the error on.
    fn fallback_later(&mut self, error: TechniqueError) -> RenderError {
        log::error!(
            "{error}; falling back to `{}`",
            crate::builtin::UNSHADOWED_ID
        );
        if let Ok(baseline) = technique::find_technique(crate::builtin::UNSHADOWED_ID)
            && let Ok(next) = instantiate(&self.gpu, baseline, &ParamValues::new())
        {
            self.technique = next;
            self.update_slots();
        }
        RenderError::Technique(error)
    }
}

fn check_size(size: UVec2) -> Result<(), RenderError> {
    if size.x == 0 || size.y == 0 || size.x > MAX_OUTPUT_SIDE || size.y > MAX_OUTPUT_SIDE {
        return Err(RenderError::Size(size.x, size.y, MAX_OUTPUT_SIDE));
    }
    Ok(())
}

/// `targets` in consecutive groups that each fit one render pass: at most
/// `max_color_attachments` of them within `max_color_attachment_bytes_per_sample` (each
/// format's render-target byte cost, aligned to its component size, as WebGPU counts them).
fn attachment_chunks<T: Clone>(
    targets: &[(T, wgpu::TextureFormat)],
    limits: &wgpu::Limits,
) -> Vec<Vec<T>> {
    let mut chunks: Vec<Vec<_>> = Vec::new();
    let mut bytes = 0u32;
    for (target, format) in targets {
        let cost = format.target_pixel_byte_cost().unwrap_or(16);
        let align = format.target_component_alignment().unwrap_or(4);
        let next = bytes.next_multiple_of(align) + cost;
        let full = chunks.last().is_none_or(|c| {
            c.len() as u32 >= limits.max_color_attachments
                || next > limits.max_color_attachment_bytes_per_sample
        });
        if full {
            chunks.push(Vec::new());
            bytes = cost;
        } else {
            bytes = next;
        }
        chunks
            .last_mut()
            .expect("pushed above")
            .push(target.clone());
    }
    chunks
}

/// Clears every visibility layer to 1 (lit), the transmittance slots in use to white and the
/// indirect target to 0, in as few passes as the device's colour-attachment limits allow.
fn clear_visibility(
    recorder: &mut PassRecorder<'_>,
    limits: &wgpu::Limits,
    visibility: &VisibilityTargets,
    transmittance: &TransmittanceTargets,
    indirect: &IndirectTarget,
) {
    let attachment = |view, value: f64| {
        Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: value,
                    g: value,
                    b: value,
                    a: value,
                }),
                store: wgpu::StoreOp::Store,
            },
        })
    };
    let lit = (visibility.layer_views.iter())
        .chain(&transmittance.slot_views)
        .map(|v| (attachment(v, 1.0), VISIBILITY_FORMAT));
    let targets: Vec<_> = lit
        .chain([(attachment(&indirect.view, 0.0), INDIRECT_FORMAT)])
        .collect();
    for chunk in attachment_chunks(&targets, limits) {
        drop(recorder.render_pass(&wgpu::RenderPassDescriptor {
            label: Some("Clear visibility"),
            color_attachments: &chunk,
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clears_fit_the_colour_attachment_limits() {
        let visibility = (VISIBILITY_FORMAT.target_pixel_byte_cost()).unwrap();
        let targets: Vec<_> = (0..20)
            .map(|i| (i, VISIBILITY_FORMAT))
            .chain([(20, INDIRECT_FORMAT)])
            .collect();
        // WebGPU's defaults: 8 attachments, 32 bytes a sample.
        let webgpu = wgpu::Limits::default();
        let chunks = attachment_chunks(&targets, &webgpu);
        let per_pass = (32 / visibility).min(8) as usize;
        assert_eq!(chunks[0].len(), per_pass);
        assert_eq!(
            chunks.concat(),
            (0..21).collect::<Vec<_>>(),
            "every target, in order"
        );
        for chunk in &chunks {
            let bytes: u32 = (chunk.iter())
                .map(|&i| targets[i].1.target_pixel_byte_cost().unwrap())
                .sum();
            assert!(chunk.len() <= 8 && bytes <= 32, "{chunk:?}: {bytes} bytes");
        }
        // A device with room for eight of them a pass.
        let roomy = wgpu::Limits {
            max_color_attachment_bytes_per_sample: 128,
            ..webgpu
        };
        let sizes: Vec<usize> = attachment_chunks(&targets, &roomy)
            .iter()
            .map(Vec::len)
            .collect();
        assert_eq!(sizes, [8, 8, 5]);
    }
}
