//! GPU structs declared once: [`gpu_struct!`](crate::gpu_struct) turns one Rust declaration
//! into the Rust type, its bytes laid out by WGSL's rules (no padding fields written by hand)
//! and the WGSL struct, registered as a shader module the shaders `#import`. No second copy
//! exists to drift, so no mirror test is needed; one workspace test checks every registered
//! struct's computed layout against naga's.
//!
//! ```
//! use zoo_host::glam::{Mat4, Vec3};
//! use zoo_host::gpu::{GpuType, gpu_bytes};
//!
//! zoo_host::gpu_struct! {
//!     "my-technique/light.wgsl" =>
//!     /// One light as the lookup reads it.
//!     #[derive(Debug, Clone, Copy, PartialEq)]
//!     pub struct MyLight {
//!         pub direction: Vec3,
//!         pub strength: f32,
//!         pub cameras: [Mat4; 2],
//!     }
//! }
//!
//! // WGSL's layout, computed: 12 + 4 bytes, then two 64-byte matrices.
//! let light = MyLight { direction: Vec3::Y, strength: 2.0, cameras: [Mat4::IDENTITY; 2] };
//! assert_eq!((MyLight::SIZE, gpu_bytes(&[light]).len()), (144, 144));
//! // Shaders `#import "my-technique/light.wgsl"` to declare it.
//! let wgsl = zoo_host::ShaderLibrary::embedded().compose("my-technique/light.wgsl").unwrap();
//! assert!(wgsl.source.contains("struct MyLight"));
//! ```
//!
//! A `gpu_struct!` type is also a [`UniformValue`](crate::kit::UniformValue), so
//! [`UniformSlots`](crate::kit::UniformSlots) and
//! [`FullscreenLightPass`](crate::kit::FullscreenLightPass) hold it.
//!
//! Field types: `f32`, `u32`, `i32`, glam's `Vec2`/`Vec3`/`Vec4`, `UVec2`..`UVec4`,
//! `IVec2`..`IVec4`, `Mat4` (WGSL vectors and `mat4x4<f32>`), fixed-size Rust arrays (WGSL
//! `array<T, N>`) and other `gpu_struct!` types (their modules are imported). Layouts follow
//! WGSL's storage rules; a struct used in a uniform buffer must also meet the uniform rules
//! (arrays of 16-byte strides), which shader validation checks.

use glam::{IVec2, IVec3, IVec4, Mat4, UVec2, UVec3, UVec4, Vec2, Vec3, Vec4};

/// A type with a WGSL host-shareable layout.
pub trait GpuType {
    /// WGSL alignment in bytes.
    const ALIGN: usize;
    /// WGSL size in bytes.
    const SIZE: usize;
    /// The WGSL type's name.
    fn wgsl_type() -> String;
    /// Shader modules the WGSL type needs (those of nested structs).
    fn imports() -> Vec<&'static str> {
        Vec::new()
    }
    /// Writes the value at the start of `out` (at least [`Self::SIZE`] bytes).
    fn write(&self, out: &mut [u8]);
}

/// A struct declared with [`gpu_struct!`](crate::gpu_struct).
pub trait GpuStruct: GpuType {
    /// The shader module its WGSL declaration is registered as.
    const MODULE: &'static str;
    /// Its members: name, WGSL type, byte offset.
    fn members() -> Vec<Member>;
}

/// One member of a [`GpuStruct`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Member {
    pub name: &'static str,
    pub wgsl_type: String,
    pub offset: usize,
}

/// `value` rounded up to a multiple of `align`.
pub const fn round_up(value: usize, align: usize) -> usize {
    value.div_ceil(align) * align
}

/// The alignment of a struct of `fields` (their alignments): the largest.
pub const fn struct_align(fields: &[usize]) -> usize {
    let mut align = 1;
    let mut k = 0;
    while k < fields.len() {
        if fields[k] > align {
            align = fields[k];
        }
        k += 1;
    }
    align
}

/// The size of a struct of `fields` ((alignment, size) each): members one after another,
/// each at the next multiple of its alignment, the end rounded up to the struct's alignment.
pub const fn struct_size(fields: &[(usize, usize)]) -> usize {
    let mut end = 0;
    let mut align = 1;
    let mut k = 0;
    while k < fields.len() {
        let (a, s) = fields[k];
        end = round_up(end, a) + s;
        if a > align {
            align = a;
        }
        k += 1;
    }
    round_up(end, align)
}

/// Writes fields one after another by WGSL's rules (what [`gpu_struct!`](crate::gpu_struct)
/// expands to).
pub struct FieldWriter<'a> {
    out: &'a mut [u8],
    end: usize,
}

impl<'a> FieldWriter<'a> {
    pub fn new(out: &'a mut [u8]) -> Self {
        FieldWriter { out, end: 0 }
    }

    /// Writes `value` at the next offset its alignment allows; returns that offset.
    pub fn field<T: GpuType>(&mut self, value: &T) -> usize {
        let offset = round_up(self.end, T::ALIGN);
        value.write(&mut self.out[offset..offset + T::SIZE]);
        self.end = offset + T::SIZE;
        offset
    }
}

/// The member offsets of a struct of `fields` ((alignment, size) each).
pub fn member_offsets(fields: &[(usize, usize)]) -> Vec<usize> {
    let mut end = 0;
    fields
        .iter()
        .map(|&(align, size)| {
            let offset = round_up(end, align);
            end = offset + size;
            offset
        })
        .collect()
}

/// The bytes of `items` as a WGSL `array<T>` holds them (a storage buffer's contents).
pub fn gpu_bytes<T: GpuType>(items: &[T]) -> Vec<u8> {
    let stride = round_up(T::SIZE, T::ALIGN);
    let mut out = vec![0; stride * items.len()];
    for (item, slot) in items.iter().zip(out.chunks_exact_mut(stride)) {
        item.write(slot);
    }
    out
}

/// The bytes of one value, padded to `slot` bytes (a uniform at dynamic offsets) when larger.
pub fn gpu_bytes_padded<T: GpuType>(value: &T, slot: usize) -> Vec<u8> {
    let mut out = vec![0; slot.max(T::SIZE)];
    value.write(&mut out);
    out
}

/// The WGSL declaration of struct `S` (named `name`, declared in `source_file`), after the
/// `imports` its members need.
pub fn wgsl_declaration<S: GpuStruct>(
    name: &str,
    source_file: &str,
    mut imports: Vec<&'static str>,
) -> String {
    let mut out = format!("// Generated from `{name}` in {source_file}; do not edit.\n");
    imports.sort_unstable();
    imports.dedup();
    for module in imports.iter().filter(|m| **m != S::MODULE) {
        out += &format!("#import \"{module}\"\n");
    }
    out += &format!("struct {name} {{\n");
    for member in S::members() {
        out += &format!("    {}: {},\n", member.name, member.wgsl_type);
    }
    out += "}\n";
    out
}

macro_rules! scalar {
    ($ty:ty, $wgsl:literal) => {
        impl GpuType for $ty {
            const ALIGN: usize = 4;
            const SIZE: usize = 4;
            fn wgsl_type() -> String {
                $wgsl.to_string()
            }
            fn write(&self, out: &mut [u8]) {
                out[..4].copy_from_slice(&self.to_ne_bytes());
            }
        }
    };
}

scalar!(f32, "f32");
scalar!(u32, "u32");
scalar!(i32, "i32");

macro_rules! vector {
    ($ty:ty, $n:literal, $align:literal, $wgsl:literal) => {
        impl GpuType for $ty {
            const ALIGN: usize = $align;
            const SIZE: usize = 4 * $n;
            fn wgsl_type() -> String {
                $wgsl.to_string()
            }
            fn write(&self, out: &mut [u8]) {
                for (k, c) in self.to_array().iter().enumerate() {
                    c.write(&mut out[4 * k..]);
                }
            }
        }
    };
}

vector!(Vec2, 2, 8, "vec2<f32>");
vector!(Vec3, 3, 16, "vec3<f32>");
vector!(Vec4, 4, 16, "vec4<f32>");
vector!(UVec2, 2, 8, "vec2<u32>");
vector!(UVec3, 3, 16, "vec3<u32>");
vector!(UVec4, 4, 16, "vec4<u32>");
vector!(IVec2, 2, 8, "vec2<i32>");
vector!(IVec3, 3, 16, "vec3<i32>");
vector!(IVec4, 4, 16, "vec4<i32>");

impl GpuType for Mat4 {
    const ALIGN: usize = 16;
    const SIZE: usize = 64;
    fn wgsl_type() -> String {
        "mat4x4<f32>".to_string()
    }
    fn write(&self, out: &mut [u8]) {
        for (k, c) in self.to_cols_array().iter().enumerate() {
            c.write(&mut out[4 * k..]);
        }
    }
}

impl<T: GpuType, const N: usize> GpuType for [T; N] {
    const ALIGN: usize = T::ALIGN;
    const SIZE: usize = N * round_up(T::SIZE, T::ALIGN);
    fn wgsl_type() -> String {
        format!("array<{}, {N}>", T::wgsl_type())
    }
    fn imports() -> Vec<&'static str> {
        T::imports()
    }
    fn write(&self, out: &mut [u8]) {
        let stride = round_up(T::SIZE, T::ALIGN);
        for (k, item) in self.iter().enumerate() {
            item.write(&mut out[k * stride..]);
        }
    }
}

/// A registered [`GpuStruct`], for the workspace test that checks every layout with naga.
pub struct RegisteredStruct {
    /// The WGSL struct's name.
    pub name: &'static str,
    /// Its shader module.
    pub module: &'static str,
    /// Its size and members as the Rust side writes them.
    pub layout: fn() -> (usize, Vec<Member>),
}

inventory::collect!(RegisteredStruct);

/// Every struct declared with [`gpu_struct!`](crate::gpu_struct) in the linked crates.
pub fn registered_structs() -> impl Iterator<Item = &'static RegisteredStruct> {
    inventory::iter::<RegisteredStruct>.into_iter()
}

/// Declares a GPU struct once (see [the module](crate::gpu::gpu_struct)): `"module.wgsl" =>`
/// then the Rust struct; the WGSL struct of the same name is registered as that module.
#[macro_export]
macro_rules! gpu_struct {
    (
        $module:literal =>
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $field_vis:vis $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[$field_meta])* $field_vis $field: $ty, )*
        }

        impl $crate::gpu::gpu_struct::GpuType for $name {
            const ALIGN: usize = $crate::gpu::gpu_struct::struct_align(&[
                $( <$ty as $crate::gpu::gpu_struct::GpuType>::ALIGN, )*
            ]);
            const SIZE: usize = $crate::gpu::gpu_struct::struct_size(&[
                $( (
                    <$ty as $crate::gpu::gpu_struct::GpuType>::ALIGN,
                    <$ty as $crate::gpu::gpu_struct::GpuType>::SIZE,
                ), )*
            ]);
            fn wgsl_type() -> String {
                stringify!($name).to_string()
            }
            fn imports() -> Vec<&'static str> {
                vec![$module]
            }
            fn write(&self, out: &mut [u8]) {
                let mut writer = $crate::gpu::gpu_struct::FieldWriter::new(out);
                $( writer.field(&self.$field); )*
            }
        }

        impl $crate::kit::UniformValue for $name {
            const SIZE: usize = <$name as $crate::gpu::gpu_struct::GpuType>::SIZE;
            const WGSL_TYPE: &'static str = stringify!($name);
            fn write_bytes(&self, out: &mut [u8]) {
                $crate::gpu::gpu_struct::GpuType::write(self, out);
            }
        }

        impl $crate::gpu::gpu_struct::GpuStruct for $name {
            const MODULE: &'static str = $module;
            fn members() -> Vec<$crate::gpu::gpu_struct::Member> {
                let offsets = $crate::gpu::gpu_struct::member_offsets(&[
                    $( (
                        <$ty as $crate::gpu::gpu_struct::GpuType>::ALIGN,
                        <$ty as $crate::gpu::gpu_struct::GpuType>::SIZE,
                    ), )*
                ]);
                let names = [$( stringify!($field), )*];
                let types = vec![$( <$ty as $crate::gpu::gpu_struct::GpuType>::wgsl_type(), )*];
                names
                    .into_iter()
                    .zip(types)
                    .zip(offsets)
                    .map(|((name, wgsl_type), offset)| $crate::gpu::gpu_struct::Member {
                        name,
                        wgsl_type,
                        offset,
                    })
                    .collect()
            }
        }

        $crate::link_anchor!("gpu struct");
        $crate::inventory::submit! {
            $crate::params::shader::GeneratedShader {
                name: $module,
                source: || {
                    let mut imports = Vec::new();
                    $( imports.extend(<$ty as $crate::gpu::gpu_struct::GpuType>::imports()); )*
                    $crate::gpu::gpu_struct::wgsl_declaration::<$name>(
                        stringify!($name),
                        file!(),
                        imports,
                    )
                },
            }
        }

        $crate::inventory::submit! {
            $crate::gpu::gpu_struct::RegisteredStruct {
                name: stringify!($name),
                module: $module,
                layout: || (
                    <$name as $crate::gpu::gpu_struct::GpuType>::SIZE,
                    <$name as $crate::gpu::gpu_struct::GpuStruct>::members(),
                ),
            }
        }
    };
}

/// Checks a registered struct against naga's layout of its generated module: every member at
/// the offset the Rust side writes it, and the same size.
pub fn check_with_naga(s: &RegisteredStruct) -> Result<(), String> {
    let composed = crate::ShaderLibrary::embedded()
        .compose(s.module)
        .map_err(|e| format!("{}: {e}", s.module))?;
    let wgsl = crate::gpu::layout::wgsl_struct(&composed.source, s.name)?;
    let (size, members) = (s.layout)();
    let rust: Vec<(String, u32)> = members
        .iter()
        .map(|m| (m.name.to_string(), m.offset as u32))
        .collect();
    if wgsl.members != rust || wgsl.size as usize != size {
        return Err(format!(
            "`{}` ({}): Rust writes {rust:?} in {size} bytes, naga lays out {:?} in {}",
            s.name, s.module, wgsl.members, wgsl.size
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, UVec2, Vec3, Vec4};

    crate::gpu_struct! {
        "test/inner.wgsl" =>
        #[derive(Debug, Clone, Copy, PartialEq)]
        struct Inner {
            direction: Vec3,
            scale: f32,
            pair: UVec2,
        }
    }

    crate::gpu_struct! {
        "test/outer.wgsl" =>
        #[derive(Debug, Clone, Copy, PartialEq)]
        struct Outer {
            count: u32,
            inner: Inner,
            point: Vec3,
            weights: [f32; 3],
            camera: Mat4,
            tail: i32,
            inners: [Inner; 2],
            colour: Vec4,
        }
    }

    fn outer() -> Outer {
        let inner = Inner {
            direction: Vec3::new(1.0, 2.0, 3.0),
            scale: 4.0,
            pair: UVec2::new(5, 6),
        };
        Outer {
            count: 7,
            inner,
            point: Vec3::new(8.0, 9.0, 10.0),
            weights: [11.0, 12.0, 13.0],
            camera: Mat4::from_cols_array(&std::array::from_fn(|k| 100.0 + k as f32)),
            tail: -1,
            inners: [inner; 2],
            colour: Vec4::splat(0.5),
        }
    }

    #[test]
    fn layouts_follow_wgsl_and_naga_agrees() {
        assert_eq!((Inner::ALIGN, Inner::SIZE), (16, 32));
        let offsets: Vec<usize> = Outer::members().iter().map(|m| m.offset).collect();
        assert_eq!(offsets, [0, 16, 48, 60, 80, 144, 160, 224]);
        assert_eq!(Outer::SIZE, 240);
        for s in registered_structs().filter(|s| s.module.starts_with("test/")) {
            check_with_naga(s).unwrap();
        }
    }

    #[test]
    fn values_land_at_their_offsets_and_arrays_use_the_stride() {
        let bytes = gpu_bytes(&[outer(), outer()]);
        assert_eq!(bytes.len(), 2 * 240);
        let word = |at: usize| u32::from_ne_bytes(bytes[at..at + 4].try_into().unwrap());
        let float = |at: usize| f32::from_bits(word(at));
        assert_eq!(word(0), 7);
        assert_eq!((float(16), float(28)), (1.0, 4.0));
        assert_eq!((word(32), word(36)), (5, 6));
        assert_eq!(
            (float(48), float(56), float(60), float(68)),
            (8.0, 10.0, 11.0, 13.0)
        );
        assert_eq!((float(80), float(140)), (100.0, 115.0));
        assert_eq!(word(144) as i32, -1);
        assert_eq!((float(160), float(192 + 12)), (1.0, 4.0));
        assert_eq!(float(224), 0.5);
        assert_eq!(word(240), 7);
        assert_eq!(gpu_bytes_padded(&outer(), 256).len(), 256);
    }

    #[test]
    fn the_generated_module_imports_nested_structs_and_validates() {
        let library = crate::ShaderLibrary::embedded();
        let text = library.source("test/outer.wgsl").unwrap();
        assert!(text.contains("#import \"test/inner.wgsl\""), "{text}");
        assert!(text.contains("    inners: array<Inner, 2>,\n"), "{text}");
        let composed = library.compose("test/outer.wgsl").unwrap();
        naga::front::wgsl::parse_str(&composed.source).unwrap();
    }

    #[test]
    fn a_wrong_layout_is_reported_with_both_sides() {
        let wrong = RegisteredStruct {
            name: "Inner",
            module: "test/inner.wgsl",
            layout: || {
                let mut members = Inner::members();
                members[1].offset = 16;
                (Inner::SIZE, members)
            },
        };
        let err = check_with_naga(&wrong).unwrap_err();
        assert!(
            err.contains("naga lays out") && err.contains("(\"scale\", 16)"),
            "{err}"
        );
    }
}
