//! The bindings and workgroup size of a stage's entry points, read from its WGSL (naga's IR),
//! so a stage's resources are declared once, in the shader, and bound by their variable names.

use naga::valid::ModuleInfo;
use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, StorageAccess, TypeInner};

/// One resource of a group as the shader declares it.
#[derive(Debug, Clone)]
pub struct ReflectedBinding {
    /// The WGSL variable name.
    pub name: String,
    /// The name of the variable's type where it is a named type (a struct).
    pub type_name: Option<String>,
    /// The layout entry the declaration implies, visible to the stages that use it.
    pub entry: wgpu::BindGroupLayoutEntry,
}

/// What a set of entry points of one module uses of its bind groups.
#[derive(Debug, Clone, Default)]
pub struct ReflectedShader {
    /// The used resources of each group, by group index and then binding number.
    pub groups: std::collections::BTreeMap<u32, Vec<ReflectedBinding>>,
    /// `@workgroup_size` of the compute entry point, if one of them is.
    pub workgroup_size: Option<[u32; 3]>,
}

impl ReflectedShader {
    /// The bindings of `group` (none where the entry points use none of it).
    pub fn group(&self, group: u32) -> &[ReflectedBinding] {
        self.groups.get(&group).map_or(&[], Vec::as_slice)
    }
}

/// Reads the bindings used by entry points `entries` of `module` (their visibility the union
/// of the stages that use them). Float textures are filterable where an entry samples them
/// with a filtering sampler (so unfilterable formats can be bound to the ones only loaded).
pub fn reflect_entries(
    module: &naga::Module,
    info: &ModuleInfo,
    entries: &[&str],
) -> Result<ReflectedShader, String> {
    let mut out = ReflectedShader::default();
    for &entry in entries {
        let (index, point) = module
            .entry_points
            .iter()
            .enumerate()
            .find(|(_, e)| e.name == entry)
            .ok_or_else(|| format!("no entry point `{entry}`"))?;
        if point.stage == naga::ShaderStage::Compute {
            if point.workgroup_size_overrides.is_some() {
                return Err(format!(
                    "`{entry}`: a workgroup size set by overrides cannot be read from the shader"
                ));
            }
            out.workgroup_size = Some(point.workgroup_size);
        }
        let visibility = match point.stage {
            naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
            _ => wgpu::ShaderStages::COMPUTE,
        };
        add_entry_uses(module, info.get_entry_point(index), visibility, &mut out)?;
    }
    for bindings in out.groups.values_mut() {
        bindings.sort_by_key(|b| b.entry.binding);
    }
    Ok(out)
}

/// Adds the bindings one entry point uses to `out`, or its stage to their visibility.
fn add_entry_uses(
    module: &naga::Module,
    uses: &naga::valid::FunctionInfo,
    visibility: wgpu::ShaderStages,
    out: &mut ReflectedShader,
) -> Result<(), String> {
    // A texture is filterable where the entry samples it with a filtering sampler.
    let filtered = |image| {
        uses.sampling_set.iter().any(|key| {
            key.image == image
                && matches!(
                    module.types[module.global_variables[key.sampler].ty].inner,
                    TypeInner::Sampler { comparison: false }
                )
        })
    };
    for (handle, var) in module.global_variables.iter() {
        let Some(binding) = var.binding.as_ref().filter(|_| !uses[handle].is_empty()) else {
            continue;
        };
        let name = (var.name.clone()).unwrap_or_else(|| format!("@binding({})", binding.binding));
        let ty =
            binding_type(module, var, filtered(handle)).map_err(|e| format!("`{name}`: {e}"))?;
        let group = out.groups.entry(binding.group).or_default();
        match group
            .iter_mut()
            .find(|b| b.entry.binding == binding.binding)
        {
            Some(known) => {
                known.entry.visibility |= visibility;
                if let (
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: known },
                        ..
                    },
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable },
                        ..
                    },
                ) = (&mut known.entry.ty, ty)
                {
                    *known |= filterable;
                }
            }
            None => group.push(ReflectedBinding {
                name,
                type_name: module.types[var.ty].name.clone(),
                entry: wgpu::BindGroupLayoutEntry {
                    binding: binding.binding,
                    visibility,
                    ty,
                    count: None,
                },
            }),
        }
    }
    Ok(())
}

/// The layout binding type of one global variable.
fn binding_type(
    module: &naga::Module,
    var: &naga::GlobalVariable,
    filterable: bool,
) -> Result<wgpu::BindingType, String> {
    let buffer = |ty| {
        Ok(wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        })
    };
    match (var.space, &module.types[var.ty].inner) {
        (AddressSpace::Uniform, _) => buffer(wgpu::BufferBindingType::Uniform),
        (AddressSpace::Storage { access }, _) => buffer(wgpu::BufferBindingType::Storage {
            read_only: !access.contains(StorageAccess::STORE),
        }),
        (AddressSpace::Handle, TypeInner::Sampler { comparison }) => {
            Ok(wgpu::BindingType::Sampler(if *comparison {
                wgpu::SamplerBindingType::Comparison
            } else {
                wgpu::SamplerBindingType::Filtering
            }))
        }
        (
            AddressSpace::Handle,
            TypeInner::Image {
                dim,
                arrayed,
                class,
            },
        ) => {
            let view_dimension = view_dimension(*dim, *arrayed);
            Ok(match *class {
                ImageClass::Sampled { kind, multi } => wgpu::BindingType::Texture {
                    sample_type: match kind {
                        ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                        ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                        _ => wgpu::TextureSampleType::Float { filterable },
                    },
                    view_dimension,
                    multisampled: multi,
                },
                ImageClass::Depth { multi } => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension,
                    multisampled: multi,
                },
                ImageClass::Storage { format, access } => wgpu::BindingType::StorageTexture {
                    access: match (
                        access.contains(StorageAccess::LOAD),
                        access.contains(StorageAccess::STORE),
                    ) {
                        _ if access.contains(StorageAccess::ATOMIC) => {
                            wgpu::StorageTextureAccess::Atomic
                        }
                        (true, true) => wgpu::StorageTextureAccess::ReadWrite,
                        (true, false) => wgpu::StorageTextureAccess::ReadOnly,
                        _ => wgpu::StorageTextureAccess::WriteOnly,
                    },
                    format: storage_format(format),
                    view_dimension,
                },
                ImageClass::External => return Err("external textures are not supported".into()),
            })
        }
        (space, _) => Err(format!("no binding type for address space {space:?}")),
    }
}

fn view_dimension(dim: ImageDimension, arrayed: bool) -> wgpu::TextureViewDimension {
    use wgpu::TextureViewDimension as D;
    match (dim, arrayed) {
        (ImageDimension::D1, _) => D::D1,
        (ImageDimension::D2, false) => D::D2,
        (ImageDimension::D2, true) => D::D2Array,
        (ImageDimension::D3, _) => D::D3,
        (ImageDimension::Cube, false) => D::Cube,
        (ImageDimension::Cube, true) => D::CubeArray,
    }
}

/// The texture format of a WGSL storage format.
fn storage_format(format: naga::StorageFormat) -> wgpu::TextureFormat {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as F;
    match format {
        S::R8Unorm => F::R8Unorm,
        S::R8Snorm => F::R8Snorm,
        S::R8Uint => F::R8Uint,
        S::R8Sint => F::R8Sint,
        S::R16Uint => F::R16Uint,
        S::R16Sint => F::R16Sint,
        S::R16Float => F::R16Float,
        S::Rg8Unorm => F::Rg8Unorm,
        S::Rg8Snorm => F::Rg8Snorm,
        S::Rg8Uint => F::Rg8Uint,
        S::Rg8Sint => F::Rg8Sint,
        S::R32Uint => F::R32Uint,
        S::R32Sint => F::R32Sint,
        S::R32Float => F::R32Float,
        S::Rg16Uint => F::Rg16Uint,
        S::Rg16Sint => F::Rg16Sint,
        S::Rg16Float => F::Rg16Float,
        S::Rgba8Unorm => F::Rgba8Unorm,
        S::Rgba8Snorm => F::Rgba8Snorm,
        S::Rgba8Uint => F::Rgba8Uint,
        S::Rgba8Sint => F::Rgba8Sint,
        S::Bgra8Unorm => F::Bgra8Unorm,
        S::Rgb10a2Uint => F::Rgb10a2Uint,
        S::Rgb10a2Unorm => F::Rgb10a2Unorm,
        S::Rg11b10Ufloat => F::Rg11b10Ufloat,
        S::R64Uint => F::R64Uint,
        S::Rg32Uint => F::Rg32Uint,
        S::Rg32Sint => F::Rg32Sint,
        S::Rg32Float => F::Rg32Float,
        S::Rgba16Uint => F::Rgba16Uint,
        S::Rgba16Sint => F::Rgba16Sint,
        S::Rgba16Float => F::Rgba16Float,
        S::Rgba32Uint => F::Rgba32Uint,
        S::Rgba32Sint => F::Rgba32Sint,
        S::Rgba32Float => F::Rgba32Float,
        S::R16Unorm => F::R16Unorm,
        S::R16Snorm => F::R16Snorm,
        S::Rg16Unorm => F::Rg16Unorm,
        S::Rg16Snorm => F::Rg16Snorm,
        S::Rgba16Unorm => F::Rgba16Unorm,
        S::Rgba16Snorm => F::Rgba16Snorm,
    }
}

/// Checks `given` (name, resource) pairs against a group's `bindings` and orders them as
/// bind-group entries: every binding given exactly once, no unknown names, and buffers,
/// textures and samplers where the shader declares them.
pub fn match_resources<'a>(
    bindings: &[ReflectedBinding],
    given: &[(&str, wgpu::BindingResource<'a>)],
) -> Result<Vec<wgpu::BindGroupEntry<'a>>, String> {
    let names = || {
        let all: Vec<&str> = bindings.iter().map(|b| b.name.as_str()).collect();
        all.join(", ")
    };
    for (k, (name, _)) in given.iter().enumerate() {
        if given[..k].iter().any(|(n, _)| n == name) {
            return Err(format!("`{name}` is given twice"));
        }
        if !bindings.iter().any(|b| b.name == *name) {
            return Err(format!(
                "`{name}` is not a binding the shader uses (it uses: {})",
                names()
            ));
        }
    }
    bindings
        .iter()
        .map(|b| {
            let resource = given
                .iter()
                .find(|(n, _)| *n == b.name)
                .map(|(_, r)| r.clone())
                .ok_or_else(|| format!("`{}` is not given", b.name))?;
            let fits = matches!(
                (&b.entry.ty, &resource),
                (
                    wgpu::BindingType::Buffer { .. },
                    wgpu::BindingResource::Buffer(_)
                ) | (
                    wgpu::BindingType::Texture { .. } | wgpu::BindingType::StorageTexture { .. },
                    wgpu::BindingResource::TextureView(_),
                ) | (
                    wgpu::BindingType::Sampler(_),
                    wgpu::BindingResource::Sampler(_)
                )
            );
            if !fits {
                return Err(format!(
                    "`{}` is declared as {} but given another kind of resource",
                    b.name,
                    kind_name(&b.entry.ty)
                ));
            }
            Ok(wgpu::BindGroupEntry {
                binding: b.entry.binding,
                resource,
            })
        })
        .collect()
}

fn kind_name(ty: &wgpu::BindingType) -> &'static str {
    match ty {
        wgpu::BindingType::Buffer { .. } => "a buffer",
        wgpu::BindingType::Sampler(_) => "a sampler",
        _ => "a texture",
    }
}

/// The names of the variables `module` declares in `group`, by binding number: what a
/// [`super::SharedGroup`]'s list of names is checked against.
pub fn declared_variables(module: &naga::Module, group: u32) -> Vec<String> {
    let mut declared: Vec<(u32, String)> = (module.global_variables.iter())
        .filter_map(|(_, var)| {
            let binding = var.binding.as_ref().filter(|b| b.group == group)?;
            Some((binding.binding, var.name.clone().unwrap_or_default()))
        })
        .collect();
    declared.sort();
    declared.into_iter().map(|(_, name)| name).collect()
}

/// Workgroups that cover `extent` invocations with `size`-invocation groups.
pub fn workgroups_over(extent: [u32; 3], size: [u32; 3]) -> [u32; 3] {
    std::array::from_fn(|k| extent[k].div_ceil(size[k].max(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOURCE: &str = r#"
struct Data { n: u32 }
@group(0) @binding(0) var<storage, read> data: Data;
@group(0) @binding(1) var<storage, read_write> out: array<u32>;
@group(0) @binding(2) var layers: texture_2d_array<u32>;
@group(0) @binding(3) var image: texture_storage_3d<rgba16float, write>;
@group(0) @binding(4) var unused: texture_2d<f32>;
@group(1) @binding(0) var<uniform> other: Data;
@group(1) @binding(1) var picture: texture_2d<f32>;
@group(1) @binding(2) var linear_sampler: sampler;

@vertex
fn vs_main() -> @builtin(position) vec4<f32> {
    return vec4<f32>(f32(other.n));
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return textureSample(picture, linear_sampler, vec2<f32>(0.5)) + vec4<f32>(f32(other.n));
}

@compute @workgroup_size(4, 2, 1)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    out[id.x] = data.n + textureLoad(layers, vec2<u32>(0u), 0, 0).x;
    textureStore(image, id, vec4<f32>(1.0));
}
"#;

    /// Entry points `entries` of [`SOURCE`], reflected.
    fn reflect(entries: &[&str]) -> Result<ReflectedShader, String> {
        let module = naga::front::wgsl::parse_str(SOURCE).unwrap();
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap();
        reflect_entries(&module, &info, entries)
    }

    /// `cs_main`'s group 0.
    fn stage() -> Vec<ReflectedBinding> {
        reflect(&["cs_main"]).unwrap().group(0).to_vec()
    }

    #[test]
    fn bindings_and_workgroup_size_come_from_the_shader() {
        let reflected = reflect(&["cs_main"]).unwrap();
        assert_eq!(reflected.workgroup_size, Some([4, 2, 1]));
        assert_eq!(reflected.groups.len(), 1, "group 1 is not used");
        let stage = stage();
        let names: Vec<_> = stage.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["data", "out", "layers", "image"], "unused left out");
        assert_eq!(stage[0].type_name.as_deref(), Some("Data"));
        let ty = |k: usize| stage[k].entry.ty;
        assert_eq!(
            ty(0),
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None
            }
        );
        assert!(matches!(
            ty(1),
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                ..
            }
        ));
        assert_eq!(
            ty(2),
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false
            }
        );
        assert_eq!(
            ty(3),
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba16Float,
                view_dimension: wgpu::TextureViewDimension::D3
            }
        );
        assert!(
            reflect(&["cs_missing"])
                .unwrap_err()
                .contains("no entry point `cs_missing`")
        );
    }

    #[test]
    fn render_entries_join_their_visibility_and_sampled_textures_filter() {
        let reflected = reflect(&["vs_main", "fs_main"]).unwrap();
        assert_eq!(reflected.workgroup_size, None);
        let group = reflected.group(1);
        let names: Vec<_> = group.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["other", "picture", "linear_sampler"]);
        assert_eq!(
            group[0].entry.visibility,
            wgpu::ShaderStages::VERTEX_FRAGMENT
        );
        assert_eq!(group[1].entry.visibility, wgpu::ShaderStages::FRAGMENT);
        assert!(matches!(
            group[1].entry.ty,
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                ..
            }
        ));
        assert!(reflected.group(0).is_empty());
    }

    #[test]
    fn resources_are_matched_by_name_and_kind() {
        let stage = stage();
        // No device here: a sampler resource cannot be made, so kinds are checked with what
        // can be; names are checked before kinds.
        let unknown = match_resources(
            &stage,
            &[("dta", wgpu::BindingResource::TextureViewArray(&[]))],
        );
        let err = unknown.unwrap_err();
        assert!(
            err.contains("`dta` is not a binding") && err.contains("data, out"),
            "{err}"
        );
        let err = match_resources(&stage, &[]).unwrap_err();
        assert_eq!(err, "`data` is not given");
        let twice = [
            ("out", wgpu::BindingResource::TextureViewArray(&[])),
            ("out", wgpu::BindingResource::TextureViewArray(&[])),
        ];
        assert!(
            match_resources(&stage, &twice)
                .unwrap_err()
                .contains("twice")
        );
    }

    #[test]
    fn workgroups_cover_the_extent() {
        assert_eq!(workgroups_over([17, 8, 3], [8, 8, 1]), [3, 1, 3]);
        assert_eq!(workgroups_over([0, 1, 1], [64, 1, 1]), [0, 1, 1]);
    }
}
