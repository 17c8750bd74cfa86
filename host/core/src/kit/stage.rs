//! [`Stage`]: the one way a technique writes a GPU pass. A stage is a shader's entry points
//! (a compute entry, a full-screen fragment, or a vertex and fragment pair) with everything
//! else read from the WGSL: which groups it uses, their layouts, the workgroup size. Groups
//! that others own ([`SharedGroup`]s: the host's frame, G-buffer and materials, a library's
//! groups, per-light uniforms) are recognised by the variables they declare; the rest are the
//! stage's own, bound by variable name ([`Stage::bind`]). No group number or descriptor is
//! written in a technique.

use crate::gpu::{PassRecorder, ShaderError};
use crate::technique::{RenderContext, TechniqueError};

use super::reflect::{ReflectedBinding, match_resources, reflect_entries, workgroups_over};

/// A bind group a stage's shader reads that something other than the stage owns and binds:
/// the host's frame, G-buffer and material groups, a library's groups, per-light uniforms.
pub trait SharedGroup {
    /// Whether the group declares `binding` (a variable a stage's shader uses).
    fn declares(&self, binding: &ReflectedBinding) -> bool;
    /// The group's layout, for pipelines.
    fn layout(&self) -> &wgpu::BindGroupLayout;
    /// The group to bind and its dynamic offsets (none before its owner has made it).
    fn bound(&self) -> Option<(&wgpu::BindGroup, &[u32])>;
    /// Whether a stage may declare variables of its own in the group's index beside the
    /// group's (see [`Joinable`]).
    fn joinable(&self) -> bool {
        false
    }
}

/// A shared group whose index a stage may join with variables of its own: WebGPU gives a
/// pipeline four groups, and a technique that reads the frame, the G-buffer, a per-light
/// uniform and a library's group has none left. Such a stage's group is its own: it binds the
/// owner's resources by name with its own ([`Stage::bind`]), and its variables take binding
/// numbers after the owner's. Stages that declare only the group's variables share it.
pub struct Joinable<G>(pub G);

impl<G: SharedGroup> SharedGroup for Joinable<G> {
    fn declares(&self, binding: &ReflectedBinding) -> bool {
        self.0.declares(binding)
    }
    fn layout(&self) -> &wgpu::BindGroupLayout {
        self.0.layout()
    }
    fn bound(&self) -> Option<(&wgpu::BindGroup, &[u32])> {
        self.0.bound()
    }
    fn joinable(&self) -> bool {
        true
    }
}

/// A shared group known by the names of the WGSL variables it declares.
pub struct NamedGroup<'a> {
    /// The variables' names.
    pub names: &'a [&'a str],
    pub layout: &'a wgpu::BindGroupLayout,
    /// The bind group, once made.
    pub group: Option<&'a wgpu::BindGroup>,
}

impl SharedGroup for NamedGroup<'_> {
    fn declares(&self, binding: &ReflectedBinding) -> bool {
        self.names.contains(&binding.name.as_str())
    }
    fn layout(&self) -> &wgpu::BindGroupLayout {
        self.layout
    }
    fn bound(&self) -> Option<(&wgpu::BindGroup, &[u32])> {
        self.group.map(|group| (group, &[] as &[u32]))
    }
}

/// What a stage's pipeline is.
enum Kind<'a> {
    Compute {
        entry: &'a str,
    },
    Render {
        vertex: &'a str,
        fragment: Option<&'a str>,
        buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
        targets: Vec<Option<wgpu::ColorTargetState>>,
        primitive: wgpu::PrimitiveState,
        depth_stencil: Option<wgpu::DepthStencilState>,
    },
}

/// A stage being described: start with [`Stage::compute`], [`Stage::fullscreen`] or
/// [`Stage::render`], adjust, then [`StageBuilder::build`].
pub struct StageBuilder<'a> {
    shader: &'a str,
    text: Option<&'a str>,
    kind: Kind<'a>,
    shared: Vec<&'a dyn SharedGroup>,
}

impl<'a> StageBuilder<'a> {
    /// Takes the shader from WGSL `text` (its `#import`s resolved from the library) instead of
    /// the library's file; the shader name still labels it.
    pub fn text(mut self, text: &'a str) -> Self {
        self.text = Some(text);
        self
    }

    /// Groups besides the host's that the shader reads and others bind (see [`SharedGroup`]).
    pub fn shared(mut self, groups: &[&'a dyn SharedGroup]) -> Self {
        self.shared.extend_from_slice(groups);
        self
    }

    /// The fragment entry of a render stage (none: a depth-only or rasterise-only pass).
    pub fn fragment(mut self, entry: &'a str) -> Self {
        if let Kind::Render { fragment, .. } = &mut self.kind {
            *fragment = Some(entry);
        }
        self
    }

    /// The vertex buffers of a render stage.
    pub fn vertex_buffers(mut self, layouts: &'a [Option<wgpu::VertexBufferLayout<'a>>]) -> Self {
        if let Kind::Render { buffers, .. } = &mut self.kind {
            *buffers = layouts;
        }
        self
    }

    /// Colour targets of a render stage, after those it has (a full-screen stage starts with
    /// the light's visibility slot).
    pub fn targets(mut self, more: &[Option<wgpu::ColorTargetState>]) -> Self {
        if let Kind::Render { targets, .. } = &mut self.kind {
            targets.extend_from_slice(more);
        }
        self
    }

    /// The primitive state of a render stage.
    pub fn primitive(mut self, state: wgpu::PrimitiveState) -> Self {
        if let Kind::Render { primitive, .. } = &mut self.kind {
            *primitive = state;
        }
        self
    }

    /// The depth-stencil state of a render stage (or none).
    pub fn depth_stencil(mut self, state: impl Into<Option<wgpu::DepthStencilState>>) -> Self {
        if let Kind::Render { depth_stencil, .. } = &mut self.kind {
            *depth_stencil = state.into();
        }
        self
    }

    /// Compiles the shader, reads its groups and creates the pipeline.
    pub fn build(self, ctx: &RenderContext<'_>) -> Result<Stage, TechniqueError> {
        let device = &ctx.gpu.device;
        let entries: Vec<&str> = match &self.kind {
            Kind::Compute { entry } => vec![entry],
            Kind::Render {
                vertex, fragment, ..
            } => [Some(*vertex), *fragment].into_iter().flatten().collect(),
        };
        let label = format!("{} {}", self.shader, entries.join("/"));
        let error = |message: String| ShaderError::Pipeline {
            label: label.clone(),
            message,
        };
        let loaded = ctx.shaders.load(device, self.shader, self.text)?;
        let reflected = reflect_entries(&loaded.ir, &loaded.info, &entries).map_err(error)?;
        let host = host_groups(ctx);
        let mut shared: Vec<&dyn SharedGroup> = host.iter().map(|g| g as _).collect();
        shared.extend_from_slice(&self.shared);
        let count = reflected.groups.keys().next_back().map_or(0, |&g| g + 1);
        let groups = (0..count)
            .map(|index| {
                let bindings = reflected.group(index);
                StageGroup::new(device, (&label, &loaded.ir), index, bindings, &shared)
            })
            .collect::<Result<Vec<_>, String>>()
            .map_err(error)?;
        let empty_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label} unused group")),
            entries: &[],
        });
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> = groups
            .iter()
            .map(|g| Some(g.layout(&shared, &empty_layout)))
            .collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} layout")),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        });
        let pipeline = create_pipeline(device, &label, &layout, &loaded.module, self.kind);
        Ok(Stage {
            workgroup_size: reflected.workgroup_size.unwrap_or([1, 1, 1]),
            empty: device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{label} unused group")),
                layout: &empty_layout,
                entries: &[],
            }),
            label,
            pipeline,
            groups,
        })
    }
}

/// The host's groups every stage may read: frame, G-buffer and materials.
fn host_groups<'c>(ctx: &'c RenderContext<'_>) -> [NamedGroup<'c>; 3] {
    [
        NamedGroup {
            names: crate::render::frame::FRAME_VARIABLES,
            layout: &ctx.frame.layout,
            group: Some(&ctx.frame.bind_group),
        },
        NamedGroup {
            names: crate::render::gbuffer::GBUFFER_VARIABLES,
            layout: &ctx.gbuffer.layout,
            group: Some(&ctx.gbuffer.bind_group),
        },
        NamedGroup {
            names: crate::render::materials::MATERIAL_VARIABLES,
            layout: &ctx.scene_buffers.materials.layout,
            group: Some(&ctx.scene_buffers.materials.bind_group),
        },
    ]
}

fn create_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    kind: Kind<'_>,
) -> StagePipeline {
    match kind {
        Kind::Compute { entry } => StagePipeline::Compute(device.create_compute_pipeline(
            &wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            },
        )),
        Kind::Render {
            vertex,
            fragment,
            buffers,
            targets,
            primitive,
            depth_stencil,
        } => StagePipeline::Render(device.create_render_pipeline(
            &wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(vertex),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive,
                depth_stencil,
                multisample: Default::default(),
                fragment: fragment.map(|entry| wgpu::FragmentState {
                    module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            },
        )),
    }
}

enum StagePipeline {
    Compute(wgpu::ComputePipeline),
    Render(wgpu::RenderPipeline),
}

/// What fills one group index of a stage.
enum StageGroup {
    /// The shader uses nothing of it.
    Unused,
    /// A [`SharedGroup`] that declares its bindings, given when recording.
    Shared(Vec<ReflectedBinding>),
    /// The stage's own, bound by name.
    Own {
        layout: wgpu::BindGroupLayout,
        bindings: Vec<ReflectedBinding>,
        /// Every variable the shader declares in the group, used by the stage or not.
        declared: Vec<String>,
    },
}

impl StageGroup {
    fn new(
        device: &wgpu::Device,
        (label, module): (&str, &naga::Module),
        index: u32,
        bindings: &[ReflectedBinding],
        shared: &[&dyn SharedGroup],
    ) -> Result<StageGroup, String> {
        if bindings.is_empty() {
            return Ok(StageGroup::Unused);
        }
        if shared_for(shared, bindings).is_some() {
            return Ok(StageGroup::Shared(bindings.to_vec()));
        }
        if let Some(b) = bindings
            .iter()
            .find(|b| shared.iter().any(|s| s.declares(b) && !s.joinable()))
        {
            return Err(format!(
                "`{}` belongs to a shared group, but its group also holds {}",
                b.name,
                names(bindings)
            ));
        }
        // Own variables, and perhaps a joinable group's, which the stage binds itself.
        let entries: Vec<_> = bindings.iter().map(|b| b.entry).collect();
        Ok(StageGroup::Own {
            layout: device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(&format!("{label} group {index}")),
                entries: &entries,
            }),
            bindings: bindings.to_vec(),
            declared: super::reflect::declared_variables(module, index),
        })
    }

    fn layout<'s>(
        &'s self,
        shared: &[&'s dyn SharedGroup],
        empty: &'s wgpu::BindGroupLayout,
    ) -> &'s wgpu::BindGroupLayout {
        match self {
            StageGroup::Unused => empty,
            StageGroup::Own { layout, .. } => layout,
            StageGroup::Shared(bindings) => shared_for(shared, bindings)
                .expect("matched when the group was made")
                .layout(),
        }
    }
}

/// The first of `shared` that declares every one of `bindings`.
fn shared_for<'s>(
    shared: &[&'s dyn SharedGroup],
    bindings: &[ReflectedBinding],
) -> Option<&'s dyn SharedGroup> {
    (shared.iter())
        .find(|s| bindings.iter().all(|b| s.declares(b)))
        .copied()
}

fn names(bindings: &[ReflectedBinding]) -> String {
    let names: Vec<String> = bindings.iter().map(|b| format!("`{}`", b.name)).collect();
    names.join(", ")
}

/// One pipeline and the groups its shader reads (see [the module](self)).
pub struct Stage {
    /// `shader entry` (or `shader vertex/fragment`): names the pipeline and its errors.
    label: String,
    pipeline: StagePipeline,
    groups: Vec<StageGroup>,
    /// Bound where the shader uses a group index not at all.
    empty: wgpu::BindGroup,
    workgroup_size: [u32; 3],
}

/// A bind group of one of a stage's own groups (from [`Stage::bind`]).
pub struct StageBindGroup {
    index: u32,
    group: wgpu::BindGroup,
}

impl Stage {
    /// A compute stage: entry `entry` of library shader `shader`.
    pub fn compute<'a>(shader: &'a str, entry: &'a str) -> StageBuilder<'a> {
        StageBuilder {
            shader,
            text: None,
            kind: Kind::Compute { entry },
            shared: Vec::new(),
        }
    }

    /// A full-screen triangle (`common/fullscreen.wgsl`'s `fullscreen_vs`, which `shader`
    /// imports) and fragment `entry`, writing a light's visibility slot (see
    /// [`super::slot`]); [`StageBuilder::targets`] adds targets after it.
    pub fn fullscreen<'a>(shader: &'a str, entry: &'a str) -> StageBuilder<'a> {
        Self::render(shader, "fullscreen_vs")
            .fragment(entry)
            .targets(&[Some(super::slot_target())])
    }

    /// A render stage from vertex entry `vertex` of `shader`, with no vertex buffers, no
    /// fragment, no targets and the default primitive state until the builder says otherwise.
    pub fn render<'a>(shader: &'a str, vertex: &'a str) -> StageBuilder<'a> {
        StageBuilder {
            shader,
            text: None,
            kind: Kind::Render {
                vertex,
                fragment: None,
                buffers: &[],
                targets: Vec::new(),
                primitive: Default::default(),
                depth_stencil: None,
            },
            shared: Vec::new(),
        }
    }

    /// The stage's label: its shader and entry points.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// A bind group of the stage's own group that declares the named `resources`, each named
    /// as its WGSL variable: every variable of the group the stage uses must be given, once,
    /// with a resource of its kind. Variables the shader declares in the group but the stage's
    /// entries do not use may be given too and are left out, so one list serves every stage
    /// of a shader.
    pub fn bind(
        &self,
        ctx: &RenderContext<'_>,
        label: &str,
        resources: &[(&str, wgpu::BindingResource<'_>)],
    ) -> Result<StageBindGroup, TechniqueError> {
        let error = |message: String| ShaderError::Pipeline {
            label: format!("{label} (for {})", self.label),
            message,
        };
        let first = resources.first().map_or("", |(name, _)| *name);
        let (index, layout, bindings, declared) = (self.groups.iter().enumerate())
            .find_map(|(index, group)| match group {
                StageGroup::Own {
                    layout,
                    bindings,
                    declared,
                } if declared.iter().any(|name| name == first) => {
                    Some((index as u32, layout, bindings, declared))
                }
                _ => None,
            })
            .ok_or_else(|| {
                error(format!(
                    "`{first}` is not a variable of the stage's own groups ({})",
                    self.own_names()
                ))
            })?;
        let used: Vec<_> = (resources.iter())
            .filter(|(name, _)| {
                bindings.iter().any(|b| b.name == *name) || !declared.iter().any(|d| d == name)
            })
            .cloned()
            .collect();
        let entries = match_resources(bindings, &used).map_err(error)?;
        let group = ctx
            .gpu
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            });
        Ok(StageBindGroup { index, group })
    }

    /// A bind group of each of the stage's own groups, from the first of `lists` whose first
    /// variable the group declares ([`Self::bind`]); lists of groups the stage does not use
    /// are skipped, so one set of lists serves every stage of a shader whose entries use
    /// different groups.
    pub fn bind_own(
        &self,
        ctx: &RenderContext<'_>,
        label: &str,
        lists: &[&[(&str, wgpu::BindingResource<'_>)]],
    ) -> Result<Vec<StageBindGroup>, TechniqueError> {
        let declares = |name: &str| {
            (self.groups.iter()).any(|group| match group {
                StageGroup::Own { declared, .. } => declared.iter().any(|d| d == name),
                _ => false,
            })
        };
        (lists.iter())
            .filter(|list| list.first().is_some_and(|(name, _)| declares(name)))
            .map(|list| self.bind(ctx, label, list))
            .collect()
    }

    fn own_names(&self) -> String {
        let own: Vec<String> = (self.groups.iter())
            .filter_map(|g| match g {
                StageGroup::Own { bindings, .. } => Some(names(bindings)),
                _ => None,
            })
            .collect();
        own.join("; ")
    }

    /// Sets the pipeline and every group of a render stage on `pass`: the host's groups,
    /// `shared` ones and the stage's `own` bind groups.
    pub fn set_on(
        &self,
        ctx: &RenderContext<'_>,
        pass: &mut wgpu::RenderPass<'_>,
        own: &[&StageBindGroup],
        shared: &[&dyn SharedGroup],
    ) -> Result<(), TechniqueError> {
        let StagePipeline::Render(pipeline) = &self.pipeline else {
            return Err(self.misuse("set on a render pass"));
        };
        pass.set_pipeline(pipeline);
        self.each_group(ctx, own, shared, |index, group, offsets| {
            pass.set_bind_group(index, group, offsets)
        })
    }

    /// Records one dispatch of a compute stage in a pass named `name`, with enough workgroups
    /// to cover `extent` invocations.
    pub fn dispatch(
        &self,
        ctx: &RenderContext<'_>,
        recorder: &mut PassRecorder<'_>,
        name: &str,
        own: &[&StageBindGroup],
        shared: &[&dyn SharedGroup],
        extent: [u32; 3],
    ) -> Result<(), TechniqueError> {
        let mut pass = recorder.compute_pass(name);
        self.dispatch_in(ctx, &mut pass, (own, shared), extent)
    }

    /// As [`Self::dispatch`], in compute pass `pass`: for a pass of many dispatches (one
    /// entry in the pass timings).
    pub fn dispatch_in(
        &self,
        ctx: &RenderContext<'_>,
        pass: &mut wgpu::ComputePass<'_>,
        (own, shared): (&[&StageBindGroup], &[&dyn SharedGroup]),
        extent: [u32; 3],
    ) -> Result<(), TechniqueError> {
        let StagePipeline::Compute(pipeline) = &self.pipeline else {
            return Err(self.misuse("dispatched"));
        };
        pass.set_pipeline(pipeline);
        self.each_group(ctx, own, shared, |index, group, offsets| {
            pass.set_bind_group(index, group, offsets)
        })?;
        let [x, y, z] = workgroups_over(extent, self.workgroup_size);
        pass.dispatch_workgroups(x, y, z);
        Ok(())
    }

    fn misuse(&self, what: &str) -> TechniqueError {
        TechniqueError::Other(format!(
            "{}: a stage of the other kind was {what}",
            self.label
        ))
    }

    /// Calls `set(index, group, offsets)` for every group of the stage, or says which is not
    /// given.
    fn each_group(
        &self,
        ctx: &RenderContext<'_>,
        own: &[&StageBindGroup],
        shared: &[&dyn SharedGroup],
        mut set: impl FnMut(u32, &wgpu::BindGroup, &[u32]),
    ) -> Result<(), TechniqueError> {
        let host = host_groups(ctx);
        let mut all: Vec<&dyn SharedGroup> = shared.to_vec();
        all.extend(host.iter().map(|g| g as &dyn SharedGroup));
        for (index, group) in self.groups.iter().enumerate() {
            let index = index as u32;
            match group {
                StageGroup::Unused => set(index, &self.empty, &[]),
                StageGroup::Shared(bindings) => {
                    let source = shared_for(&all, bindings).ok_or_else(|| {
                        self.not_given(format!("the shared group of {}", names(bindings)))
                    })?;
                    let (group, offsets) =
                        source.bound().ok_or_else(TechniqueError::not_prepared)?;
                    set(index, group, offsets);
                }
                StageGroup::Own { bindings, .. } => {
                    let given = own.iter().find(|g| g.index == index).ok_or_else(|| {
                        self.not_given(format!("the group of {}", names(bindings)))
                    })?;
                    set(index, &given.group, &[]);
                }
            }
        }
        Ok(())
    }

    fn not_given(&self, what: String) -> TechniqueError {
        TechniqueError::Other(format!("{}: {what} was not given", self.label))
    }
}

#[cfg(test)]
mod tests {
    use super::super::reflect::declared_variables;
    use crate::render::{frame, gbuffer, materials};

    #[test]
    fn the_host_groups_names_are_their_shaders() {
        let library = crate::ShaderLibrary::embedded();
        for (shader, group, names) in [
            ("common/frame.wgsl", 0, frame::FRAME_VARIABLES),
            ("common/gbuffer.wgsl", 1, gbuffer::GBUFFER_VARIABLES),
            ("common/materials.wgsl", 1, materials::MATERIAL_VARIABLES),
        ] {
            // (The G-buffer's helpers read the camera.)
            let text = format!("#import \"common/frame.wgsl\"\n#import \"{shader}\"\n");
            let (_, module) = library.validate_source("test.wgsl", &text).unwrap();
            let declared = declared_variables(&module, group);
            assert_eq!(declared, names, "{shader}");
        }
    }
}
