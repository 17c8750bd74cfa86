//! Instance, adapter, device and queue, created once and shared by the renderer and techniques.

use std::sync::{Arc, Mutex};

use crate::gpu::adapter::{AdapterError, choose_adapter};
use crate::technique;

/// Why no GPU device could be created.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter can run the host (each one found is listed with its reasons).
    #[error(transparent)]
    Adapter(#[from] AdapterError),
    /// The adapter refused the device.
    #[error("the adapter refused to create a device: {0}")]
    Device(String),
}

/// The shared GPU objects.
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// On wgpu's GL backend only: the buffer [`Self::order_raster_before_compute`] moves.
    raster_fence: Option<wgpu::Buffer>,
}

impl GpuContext {
    /// Creates a headless context. The backend and adapter honour `WGPU_BACKEND` and
    /// `WGPU_ADAPTER_NAME`; the device gets every feature that a registered technique needs or
    /// would like and the adapter has, plus timestamp queries where available.
    pub fn new_headless() -> Result<GpuContext, GpuError> {
        pollster::block_on(Self::new_headless_async())
    }

    /// Creates a headless context on one of `backends` only (for example to run on wgpu's GL
    /// backend beside Vulkan in one process); `WGPU_ADAPTER_NAME` still applies.
    pub fn new_headless_on(backends: wgpu::Backends) -> Result<GpuContext, GpuError> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        descriptor.backends = backends;
        pollster::block_on(Self::create(descriptor))
    }

    /// Creates a headless context as [`Self::new_headless`] does, without the `removed`
    /// features (to run techniques as on a device that lacks them).
    pub fn new_headless_without(removed: wgpu::Features) -> Result<GpuContext, GpuError> {
        let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        pollster::block_on(Self::create_restricted(descriptor, removed, None))
    }

    /// Creates a headless context as [`Self::new_headless`] does, with `limits` instead of
    /// the adapter's (WebGPU's defaults, for example, to run techniques as on a browser's
    /// device).
    pub fn new_headless_limited(limits: wgpu::Limits) -> Result<GpuContext, GpuError> {
        let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let removed = wgpu::Features::empty();
        pollster::block_on(Self::create_restricted(descriptor, removed, Some(limits)))
    }

    async fn new_headless_async() -> Result<GpuContext, GpuError> {
        Self::create(wgpu::InstanceDescriptor::new_without_display_handle_from_env()).await
    }

    async fn create(descriptor: wgpu::InstanceDescriptor) -> Result<GpuContext, GpuError> {
        Self::create_restricted(descriptor, wgpu::Features::empty(), None).await
    }

    async fn create_restricted(
        descriptor: wgpu::InstanceDescriptor,
        removed: wgpu::Features,
        limits: Option<wgpu::Limits>,
    ) -> Result<GpuContext, GpuError> {
        let backends = descriptor.backends;
        let instance = wgpu::Instance::new(descriptor);
        let adapter = select_adapter(&instance, backends).await?;
        let mut descriptor = Self::device_descriptor(&adapter, "shadow-zoo device", removed);
        if let Some(limits) = limits {
            descriptor.required_limits = limits;
        }
        let (device, queue) = adapter
            .request_device(&descriptor)
            .await
            .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Self::from_parts(instance, adapter, device, queue))
    }

    /// Features to request from `adapter`: the union of what techniques need, limited to what
    /// the adapter has.
    pub fn wanted_features(adapter: &wgpu::Adapter) -> wgpu::Features {
        // Query results are read back as each frame ends, which a browser cannot wait for:
        // there passes are timed on the CPU (as submitted).
        let mut wanted = if cfg!(target_arch = "wasm32") {
            wgpu::Features::empty()
        } else {
            wgpu::Features::TIMESTAMP_QUERY
                | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
                | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES
                | wgpu::Features::PIPELINE_STATISTICS_QUERY
        };
        for registration in technique::registry() {
            wanted |= (registration.required_features)() | (registration.optional_features)();
        }
        wanted & adapter.features()
    }

    /// The device to request from `adapter`: [`Self::wanted_features`] less `removed`, and the
    /// adapter's limits. Experimental features (hardware ray queries) are opted into only when
    /// a technique would use one the adapter has.
    // The one unsafe block of the project: wgpu's opt-in token for experimental features.
    #[allow(unsafe_code)]
    pub fn device_descriptor(
        adapter: &wgpu::Adapter,
        label: &'static str,
        removed: wgpu::Features,
    ) -> wgpu::DeviceDescriptor<'static> {
        let features = Self::wanted_features(adapter) - removed;
        let experimental = if features.intersects(wgpu::Features::all_experimental_mask()) {
            // SAFETY: wgpu's opt-in to features it marks experimental; only those techniques
            // declare are requested, and only where the adapter has them. (The hardware ray
            // query path is checked against the portable one by rt-shadows' tests.)
            unsafe { wgpu::ExperimentalFeatures::enabled() }
        } else {
            wgpu::ExperimentalFeatures::disabled()
        };
        wgpu::DeviceDescriptor {
            label: Some(label),
            required_features: features,
            required_limits: adapter.limits(),
            experimental_features: experimental,
            ..Default::default()
        }
    }

    /// Wraps objects created elsewhere (the viewer's eframe device, for example).
    pub fn from_parts(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> GpuContext {
        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        let sink = uncaptured.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            let message = error_chain(&error);
            log::error!("wgpu: {message}");
            if let Ok(mut errors) = sink.lock() {
                errors.push(message);
            }
        }));
        let lost = uncaptured.clone();
        device.set_device_lost_callback(move |reason, message| {
            let message = format!("the GPU device was lost ({reason:?}): {message}");
            log::error!("{message}");
            if let Ok(mut errors) = lost.lock() {
                errors.push(message);
            }
        });
        let info = adapter.get_info();
        let raster_fence = (info.backend == wgpu::Backend::Gl).then(|| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("GL raster-before-compute fence"),
                size: 4,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        GpuContext {
            instance,
            adapter,
            device,
            queue,
            info,
            uncaptured,
            raster_fence,
        }
    }

    /// Makes compute passes recorded next in `encoder` see what the render passes before them
    /// wrote (a G-buffer, a shadow map). wgpu's barriers order this on Vulkan, Metal, DX12 and
    /// WebGPU; its GL backend issues a memory barrier only after shader storage writes, and
    /// Mesa's llvmpipe can run a compute dispatch while rasterisation it has queued is still
    /// unfinished (the frustum-traced technique read a G-buffer half drawn there, one frame
    /// in some tens). On GL a storage-write transition of a small buffer issues that barrier,
    /// and the driver finishes the rasterisation first; elsewhere this does nothing.
    pub fn order_raster_before_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some(fence) = &self.raster_fence else {
            return;
        };
        for state in [
            wgpu::BufferUses::STORAGE_READ_WRITE,
            wgpu::BufferUses::COPY_DST,
        ] {
            let transition = wgpu::BufferTransition {
                buffer: fence,
                state,
            };
            encoder.transition_resources(std::iter::once(transition), std::iter::empty());
        }
    }

    /// One line naming the adapter, backend and driver.
    pub fn describe(&self) -> String {
        let i = &self.info;
        format!(
            "{} ({:?}, {:?} backend, driver {} {})",
            i.name, i.device_type, i.backend, i.driver, i.driver_info
        )
    }

    /// Whether GPU timestamps can be written at pass boundaries.
    pub fn has_timestamps(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Errors reported outside any error scope since the last call.
    pub fn take_uncaptured_errors(&self) -> Vec<String> {
        self.uncaptured
            .lock()
            .map(|mut e| std::mem::take(&mut *e))
            .unwrap_or_default()
    }

    /// Blocks until all submitted work is done.
    pub fn wait_idle(&self) {
        if let Err(e) = self.device.poll(wgpu::PollType::wait_indefinitely()) {
            log::error!("device poll failed: {e}");
        }
    }

    /// Runs `f` inside a validation error scope and returns the first validation error.
    pub fn validation_scope<T>(&self, f: impl FnOnce() -> T) -> (T, Option<String>) {
        let (value, error) = validation_scope(&self.device, f);
        (value, error.map(|e| error_chain(&e)))
    }
}

/// Runs `f` inside a validation error scope of `device` and returns the first validation
/// error. A browser resolves a scope only once control is back in its event loop, which a
/// frame cannot wait for: there `f` runs unscoped, and its errors reach the uncaptured-error
/// handler of [`GpuContext::from_parts`] and fail the next frame.
pub fn validation_scope<T>(
    device: &wgpu::Device,
    f: impl FnOnce() -> T,
) -> (T, Option<wgpu::Error>) {
    if cfg!(target_arch = "wasm32") {
        return (f(), None);
    }
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    (value, pollster::block_on(scope.pop()))
}

/// An error and all its causes on one line.
pub fn error_chain(error: &dyn std::error::Error) -> String {
    let mut message = error.to_string().trim().to_string();
    let mut source = error.source();
    while let Some(inner) = source {
        let text = inner.to_string();
        if !message.contains(text.trim()) {
            message.push_str(": ");
            message.push_str(text.trim());
        }
        source = inner.source();
    }
    message
}

async fn select_adapter(
    instance: &wgpu::Instance,
    backends: wgpu::Backends,
) -> Result<wgpu::Adapter, AdapterError> {
    let adapters = instance.enumerate_adapters(backends).await;
    choose_adapter(&adapters, backends)
}
