//! The `ShadowTechnique` contract and the link-time registry of techniques.
//!
//! A technique is a crate under `plugins/` that implements [`ShadowTechnique`] and registers a
//! [`TechniqueRegistration`] with [`register_technique!`](crate::register_technique). The host
//! renders the G-buffer, clears the visibility storage to 1 (lit), lets the technique record its
//! passes, and shades every technique identically from the visibility it wrote.

use crate::gpu::{GpuContext, PassRecorder, ShaderError, ShaderLibrary};
pub use crate::params::ParamUpdate;
use crate::params::{ParamError, ParamSpec, ParamValues};
use crate::render::{
    FrameBindings, GBuffer, IndirectTarget, SceneBuffers, SlotAssignment, SlotRequest,
    TransmittanceTargets, VisibilityTargets,
};
use crate::scene::{Camera, Light, LightKind, Scene};

/// Creates a technique instance for a device and validated parameter values.
pub type TechniqueFactory =
    fn(&GpuContext, &ParamValues) -> Result<Box<dyn ShadowTechnique>, TechniqueError>;

/// Static description of a technique, registered at link time.
pub struct TechniqueRegistration {
    /// Package that registered it (filled in by [`register_technique!`](crate::register_technique)).
    pub package: &'static str,
    /// Stable identifier used on the command line and in reports (`sm-pcf`).
    pub id: &'static str,
    /// Display name.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The seed, paper or thesis it follows.
    pub source: &'static str,
    /// Its documentation (parameters, debug views, measured accuracy and cost, limits): the
    /// crate's `README.md` through `include_str!`, shown by the viewer; empty without one.
    pub readme: &'static str,
    /// Light kinds it computes visibility for; others are reported as unsupported.
    pub light_kinds: &'static [LightKind],
    /// Whether it adds light (indirect illumination into [`RenderContext::indirect`]) besides
    /// the lights' visibility. The scene's constant ambient stands in for indirect light, so
    /// the host drops it while such a technique is active; such a technique may be brighter
    /// than `unshadowed`, and the judge scores its indirect light against a one-bounce
    /// reference.
    pub adds_light: bool,
    /// How its shadows treat alpha-masked casters (foliage, fences): alpha-tested like the
    /// reference (the default), or whole, where the method cannot follow a texture.
    pub masked_casters: MaskedCasters,
    /// Device features it cannot run without.
    pub required_features: fn() -> wgpu::Features,
    /// Device features it uses when present.
    pub optional_features: fn() -> wgpu::Features,
    /// Device limits it needs.
    pub required_limits: fn() -> wgpu::Limits,
    /// Downlevel capabilities it needs beyond the host's (compute shaders, indirect draws...),
    /// for adapters that are not fully WebGPU-compliant such as wgpu's GL backend.
    pub required_downlevel: fn() -> wgpu::DownlevelFlags,
    /// Its parameter schema (usually `MyParams::schema`).
    pub params: fn() -> Vec<ParamSpec>,
    /// Creates an instance for the given device and validated parameter values.
    pub create: TechniqueFactory,
}

inventory::collect!(TechniqueRegistration);

/// How a technique's shadows treat casters with an alpha mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaskedCasters {
    /// Light passes through the mask's holes, as in the reference.
    AlphaTested,
    /// The whole surface casts a shadow, holes included: shadow volumes extrude silhouette
    /// edges of triangles, which cannot follow a texture.
    Opaque,
}

impl MaskedCasters {
    /// How `list`, the contact sheet and the judge's report name it.
    pub fn describe(self) -> &'static str {
        match self {
            MaskedCasters::AlphaTested => "masked casters alpha-tested",
            MaskedCasters::Opaque => "masked casters opaque",
        }
    }
}

impl std::fmt::Debug for TechniqueRegistration {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TechniqueRegistration")
            .field("id", &self.id)
            .field("package", &self.package)
            .finish_non_exhaustive()
    }
}

impl TechniqueRegistration {
    /// Values for the fields a registration leaves out (`register_technique!` fills them in):
    /// no features, downlevel capabilities or parameters, and WebGPU's downlevel limits.
    pub const DEFAULTS: TechniqueRegistration = TechniqueRegistration {
        package: "",
        id: "",
        name: "",
        description: "",
        source: "",
        readme: "",
        light_kinds: &[],
        adds_light: false,
        masked_casters: MaskedCasters::AlphaTested,
        required_features: wgpu::Features::empty,
        optional_features: wgpu::Features::empty,
        required_limits: wgpu::Limits::downlevel_defaults,
        required_downlevel: wgpu::DownlevelFlags::empty,
        params: Vec::new,
        create: |_, _| {
            Err(TechniqueError::Other(
                "registered without `create:` (register_technique! needs a factory)".into(),
            ))
        },
    };

    /// Whether it supports lights of `kind`.
    pub fn supports(&self, kind: LightKind) -> bool {
        self.light_kinds.contains(&kind)
    }

    /// Why it cannot run on `gpu`, if it cannot.
    pub fn unavailable_reason(&self, gpu: &GpuContext) -> Option<String> {
        let missing = (self.required_features)() - gpu.device.features();
        if !missing.is_empty() {
            return Some(format!("needs device features {missing:?}"));
        }
        let downlevel =
            (self.required_downlevel)() - gpu.adapter.get_downlevel_capabilities().flags;
        if !downlevel.is_empty() {
            let names: Vec<&str> = downlevel.iter_names().map(|(name, _)| name).collect();
            return Some(format!(
                "needs downlevel capabilities {} ({:?} backend)",
                names.join(", "),
                gpu.info.backend
            ));
        }
        let mut failed = Vec::new();
        (self.required_limits)().check_limits_with_fail_fn(
            &gpu.device.limits(),
            false,
            |name, wanted, allowed| failed.push(format!("{name} {wanted} (device: {allowed})")),
        );
        (!failed.is_empty()).then(|| format!("needs limits {}", failed.join(", ")))
    }

    /// Whether it treats the masked casters of `scene` as opaque (the scene has some and the
    /// technique declares [`MaskedCasters::Opaque`]).
    pub fn masks_opaque_in(&self, scene: &Scene) -> bool {
        self.masked_casters == MaskedCasters::Opaque && scene.has_masked_casters()
    }

    /// Comma-separated supported light kinds.
    pub fn light_kind_names(&self) -> String {
        self.light_kinds
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(",")
    }
}

/// Every registered technique, sorted by id. Duplicate ids, and registrations without an id, a
/// name or light kinds, are programming errors and panic at first use, naming the package or
/// both descriptions.
pub fn registry() -> Vec<&'static TechniqueRegistration> {
    let mut all: Vec<_> = inventory::iter::<TechniqueRegistration>
        .into_iter()
        .collect();
    all.sort_by_key(|r| r.id);
    for r in &all {
        assert!(
            !r.id.is_empty() && !r.name.is_empty() && !r.light_kinds.is_empty(),
            "a technique registered by {} lacks an id, a name or light kinds",
            r.package
        );
    }
    for pair in all.windows(2) {
        assert!(
            pair[0].id != pair[1].id,
            "two techniques are registered as `{}`: \"{}\" and \"{}\"",
            pair[0].id,
            pair[0].description,
            pair[1].description
        );
    }
    all
}

/// Looks up a technique by id.
pub fn find_technique(id: &str) -> Result<&'static TechniqueRegistration, TechniqueError> {
    let all = registry();
    all.iter()
        .copied()
        .find(|r| r.id == id)
        .ok_or_else(|| TechniqueError::Unknown {
            id: id.to_string(),
            known: all.iter().map(|r| r.id).collect::<Vec<_>>().join(", "),
        })
}

/// Keeps the registrations of the module it is invoked in when the crate is linked into a
/// WebAssembly module. Registrations are statics that nothing references; a native linker
/// keeps them (rustc hands it a list of them), but rustc cannot write that list for wasm-ld,
/// which then drops every object file of an rlib that no symbol is needed from, plugins
/// included. An exported symbol beside the registrations is needed from each. Used by the
/// registering macros; `$kind` keeps names of different macros apart.
#[doc(hidden)]
#[macro_export]
macro_rules! link_anchor {
    ($kind:literal) => {
        const _: () = {
            // An exported name is all this unsafe attribute adds: the function does nothing.
            #[allow(unsafe_code)]
            #[unsafe(export_name = concat!(
                        "zoo_link:", $kind, ":", module_path!(), ":", line!(), ":", column!()
                    ))]
            extern "C" fn link_anchor() {}
        };
    };
}

/// Registers a technique. Takes the fields of [`TechniqueRegistration`] except `package`,
/// which is set to the calling crate's package name. `id`, `name`, `description`, `source`,
/// `light_kinds` and `create` are required (the registry rejects a registration without an
/// id, name or light kinds); the others default to [`TechniqueRegistration::DEFAULTS`] (no
/// features or downlevel needs, WebGPU's downlevel limits, no parameters):
///
/// ```
/// use zoo_host::technique::{Changes, RenderContext, ShadowTechnique, TechniqueResult};
/// use zoo_host::{LightKind, PassRecorder};
///
/// /// Leaves every light's visibility as the host cleared it (1: lit).
/// struct AlwaysLit;
///
/// impl ShadowTechnique for AlwaysLit {
///     fn prepare(&mut self, _: &RenderContext<'_>, _: Changes) -> TechniqueResult {
///         Ok(())
///     }
///     fn record(&mut self, _: &RenderContext<'_>, _: &mut PassRecorder<'_>) -> TechniqueResult {
///         Ok(())
///     }
/// }
///
/// zoo_host::register_technique! {
///     id: "always-lit",
///     name: "Always lit",
///     description: "Every light visible everywhere",
///     source: "the example of `register_technique!`",
///     light_kinds: &[LightKind::Directional, LightKind::Point],
///     create: |_, _| Ok(Box::new(AlwaysLit)),
/// }
///
/// let registered = zoo_host::find_technique("always-lit").unwrap();
/// assert_eq!(registered.package, "zoo-host");
/// ```
#[macro_export]
macro_rules! register_technique {
    ($($field:ident : $value:expr),* $(,)?) => {
        $crate::link_anchor!("technique");
        $crate::inventory::submit! {
            {
                // A registration that names every field leaves nothing to the defaults.
                #[allow(clippy::needless_update)]
                let registration = $crate::technique::TechniqueRegistration {
                    package: env!("CARGO_PKG_NAME"),
                    $($field: $value,)*
                    ..$crate::technique::TechniqueRegistration::DEFAULTS
                };
                registration
            }
        }
    };
}

/// The value of counter `name` among `counters` (from [`crate::Renderer::wait_for_counters`]
/// or [`ShadowTechnique::counters`]), or `None` where it is not counted.
pub fn counter(counters: &[(String, f64)], name: &str) -> Option<f64> {
    (counters.iter())
        .find(|(n, _)| n == name)
        .map(|(_, value)| *value)
}

/// Errors a technique reports. The host disables a technique that returns one.
#[derive(Debug, Clone, thiserror::Error)]
pub enum TechniqueError {
    /// No technique has that id.
    #[error("unknown technique `{id}` (registered: {known})")]
    Unknown { id: String, known: String },
    /// A parameter was rejected.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A shader failed to compile.
    #[error(transparent)]
    Shader(#[from] ShaderError),
    /// The device lacks something the technique needs.
    #[error("{id} cannot run here: {reason}")]
    Unavailable { id: String, reason: String },
    /// wgpu reported a validation error while preparing or recording.
    #[error("{id}: GPU validation error: {message}")]
    Validation { id: String, message: String },
    /// The technique panicked.
    #[error("{id} panicked: {message}")]
    Panicked { id: String, message: String },
    /// Anything else.
    #[error("{0}")]
    Other(String),
}

impl TechniqueError {
    /// `record` was called before `prepare` made the technique's GPU objects.
    pub fn not_prepared() -> TechniqueError {
        TechniqueError::Other("recorded before it was prepared".into())
    }
}

/// The result of a technique's methods and factory (`()` unless given).
pub type TechniqueResult<T = ()> = Result<T, TechniqueError>;

/// What a resource is, for debug views and the memory table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResourceKind {
    Texture,
    Buffer,
}

/// How a viewable texture is displayed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViewMapping {
    /// Depth values, remapped from [min, max] to black..white.
    Depth { min: f32, max: f32 },
    /// A float texture's channels as colour, remapped from [min, max].
    Color { min: f32, max: f32 },
    /// One float channel as greyscale, remapped from [min, max].
    Channel { channel: u32, min: f32, max: f32 },
    /// Unsigned integers (counts, ids) shown with a false-colour palette.
    Integer,
    /// One channel of an integer texture holding the bits of 32-bit floats (textures every
    /// device can render into) as greyscale, remapped from [min, max].
    FloatBits { channel: u32, min: f32, max: f32 },
}

/// How reports name a light that adds nothing to a technique's indirect light, and why
/// ([`ShadowTechnique::unbounced`]).
pub fn unbounced_sentence(light: usize, kind: LightKind, why: &str) -> String {
    format!(
        "light {light} ({}) adds no indirect light: {why}",
        kind.name()
    )
}

/// A technique resource as listed in the memory table and debug view menu.
#[derive(Debug, Clone, PartialEq)]
pub struct ResourceInfo {
    pub name: String,
    pub kind: ResourceKind,
    /// Width, height and layers (textures) or element count, 1, 1 (buffers).
    pub size: [u32; 3],
    /// Texture format or element type.
    pub format: String,
    /// GPU memory in bytes.
    pub bytes: u64,
    /// Whether [`ShadowTechnique::debug_view`] can show it.
    pub viewable: bool,
}

impl ResourceInfo {
    /// Describes a texture (single mip level).
    pub fn texture(
        name: impl Into<String>,
        texture: &wgpu::Texture,
        viewable: bool,
    ) -> ResourceInfo {
        let format = texture.format();
        let texel = format
            .block_copy_size(None)
            .or_else(|| format.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
            .unwrap_or(4) as u64;
        let size = texture.size();
        ResourceInfo {
            name: name.into(),
            kind: ResourceKind::Texture,
            size: [size.width, size.height, size.depth_or_array_layers],
            format: format!("{format:?}"),
            bytes: texel
                * size.width as u64
                * size.height as u64
                * size.depth_or_array_layers as u64,
            viewable,
        }
    }

    /// Describes a buffer of `element` values.
    pub fn buffer(name: impl Into<String>, buffer: &wgpu::Buffer, element: &str) -> ResourceInfo {
        ResourceInfo {
            name: name.into(),
            kind: ResourceKind::Buffer,
            size: [buffer.size() as u32, 1, 1],
            format: element.to_string(),
            bytes: buffer.size(),
            viewable: false,
        }
    }
}

/// A texture view offered for display.
pub struct DebugImage<'a> {
    /// A single-layer 2D view.
    pub view: &'a wgpu::TextureView,
    /// How to show it.
    pub mapping: ViewMapping,
}

/// An axis of a 3D texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VolumeAxis {
    /// Across x: z runs across the screen, y up.
    X,
    /// Across y: x runs across the screen, z up.
    Y,
    /// Across z: x runs across the screen, y up.
    Z,
}

/// A slice of a 3D texture across `axis` at texel `index` (clamped to the volume), shown with
/// the other two axes across and up the screen (X: z, y; Y: x, z; Z: x, y).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VolumeSlice {
    /// The axis the slice is taken across.
    pub axis: VolumeAxis,
    /// The texel along that axis.
    pub index: u32,
}

/// A slice of a 3D texture offered for display (light propagation volumes, voxel grids).
pub struct DebugVolume<'a> {
    /// A 3D view of a float texture.
    pub view: &'a wgpu::TextureView,
    /// How to show its values (`Color` or `Channel`).
    pub mapping: ViewMapping,
    /// The slice to show.
    pub slice: VolumeSlice,
}

/// What changed since the last [`ShadowTechnique::prepare`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Changes {
    /// First call, or a new scene.
    pub scene: bool,
    /// Light positions, directions or count.
    pub lights: bool,
    /// Output resolution.
    pub resolution: bool,
    /// The camera.
    pub camera: bool,
    /// Parameters applied in place by [`ShadowTechnique::update_params`].
    pub params: bool,
}

impl Changes {
    /// Everything changed (the first prepare).
    pub const ALL: Changes = Changes {
        scene: true,
        lights: true,
        resolution: true,
        camera: true,
        params: true,
    };
}

/// Everything a technique may read while preparing and recording a frame.
pub struct RenderContext<'a> {
    pub gpu: &'a GpuContext,
    pub shaders: &'a ShaderLibrary,
    pub scene: &'a Scene,
    /// Shared vertex, index and adjacency buffers.
    pub scene_buffers: &'a SceneBuffers,
    /// Camera, lights and objects (bind group 0 by convention, `common/frame.wgsl`).
    pub frame: &'a FrameBindings,
    /// G-buffer textures (bind group 1 by convention, `common/gbuffer.wgsl`) and depth-stencil.
    pub gbuffer: &'a GBuffer,
    /// Where visibility goes: one (layer, channel) slot per light.
    pub visibility: &'a VisibilityTargets,
    /// The colour each light keeps through translucent casters: one layer per visibility slot,
    /// cleared to white, when the technique [writes it](ShadowTechnique::writes_transmittance).
    pub transmittance: &'a TransmittanceTargets,
    /// Indirect light for techniques that add light (see [`IndirectTarget`]), cleared to 0.
    pub indirect: &'a IndirectTarget,
    /// The current camera (may differ from the scene's when animated).
    pub camera: &'a Camera,
    /// The current lights.
    pub lights: &'a [Light],
    /// Output size in pixels.
    pub size: glam::UVec2,
    /// The technique resource being shown this frame, if any: work that only feeds a debug
    /// view can be skipped otherwise.
    pub debug_view: Option<&'a str>,
    /// Whether work from earlier frames whose inputs did not change may be kept (shadow maps of
    /// lights that did not move); when false, the frame does all of its work (for measuring
    /// it).
    pub reuse_unchanged: bool,
}

/// A shadow technique instance. Created by its registration's factory; dropping it frees its
/// GPU resources.
pub trait ShadowTechnique: Send {
    /// Its GPU resources, for debug views and the memory table.
    fn resources(&self) -> Vec<ResourceInfo> {
        Vec::new()
    }

    /// Which visibility slot each light writes, for the current lights and camera. The default
    /// gives every light its own; a technique that writes a light's visibility only inside
    /// its influence may share slots between lights whose influences do not overlap
    /// ([`SlotAssignment::packed`]), or colour the lights itself. Called when the technique or
    /// the lights change, and on camera moves when [`Self::slots_follow_camera`]. An error
    /// (an assignment over the technique's cap, naming the lights) disables the technique.
    fn assign_slots(&self, request: &SlotRequest<'_>) -> TechniqueResult<SlotAssignment> {
        Ok(SlotAssignment::one_per_light(request.lights.len()))
    }

    /// Whether [`Self::assign_slots`] depends on the camera (it is called again whenever the
    /// camera moves).
    fn slots_follow_camera(&self) -> bool {
        false
    }

    /// Whether it writes a transmittance colour per light ([`RenderContext::transmittance`])
    /// in `scene`, for translucent casters whose shadows are coloured. Techniques that treat translucent
    /// casters as opaque leave it `false`.
    fn writes_transmittance(&self, _scene: &Scene) -> bool {
        false
    }

    /// Frames a still view takes to converge, for techniques that accumulate over frames
    /// while nothing moves; the judge renders that many before it measures. 1 (the default)
    /// for techniques whose every frame is complete.
    fn frames_to_converge(&self) -> u32 {
        1
    }

    /// Creates or resizes resources after the scene, lights, resolution or camera changed.
    fn prepare(&mut self, ctx: &RenderContext<'_>, changes: Changes) -> Result<(), TechniqueError>;

    /// Records this frame's passes. Visibility has been cleared to 1 (lit) for every slot.
    fn record(
        &mut self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
    ) -> Result<(), TechniqueError>;

    /// A viewable resource by name, for the debug view.
    fn debug_view(&self, _resource: &str) -> Option<DebugImage<'_>> {
        None
    }

    /// A slice of a viewable 3D resource by name, for the debug view (asked when
    /// [`Self::debug_view`] has no 2D image of that name).
    fn debug_volume(&self, _resource: &str) -> Option<DebugVolume<'_>> {
        None
    }

    /// Takes new, validated parameter values without being rebuilt when it can (a filter
    /// radius, a debug choice), or asks for a new instance. The default always rebuilds.
    fn update_params(&mut self, _values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        Ok(ParamUpdate::Rebuild)
    }

    /// For a technique that adds light: why `light` adds nothing to its indirect light (a kind
    /// of light it renders no bounce for), a sentence `compare`'s report and the viewer show
    /// beside its indirect light's error; `None` for the lights that bounce (the default).
    fn unbounced(&self, _light: &Light) -> Option<String> {
        None
    }

    /// What it cannot meet for the current scene and lights (a limit of the device that
    /// leaves part of its output out, for example), each a sentence naming the technique:
    /// `compare`'s report and the viewer show them beside its results. Empty (the default)
    /// where it renders what it should.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }

    /// Workload counters from the newest frame whose counters have arrived (silhouette
    /// edges, VPLs, ...); read back without stalling, so they may lag a frame or two.
    fn counters(&self) -> Vec<(String, f64)> {
        Vec::new()
    }
}
