//! Checks that a Rust struct uploaded to the GPU has the layout of the WGSL struct it mirrors
//! (member offsets and size, read from the shader with naga), so the two cannot drift apart.
//!
//! ```
//! use zoo_host::gpu::layout::{SizeRule, check_mirror};
//!
//! #[repr(C)]
//! struct Span {
//!     start: [f32; 3],
//!     length: f32,
//! }
//! let wgsl = "struct Span { start: vec3<f32>, length: f32 }";
//! let (size, fields) = zoo_host::mirror_fields!(Span { start, length });
//! check_mirror(wgsl, "Span", size, &fields, SizeRule::Equal).unwrap();
//! ```
//!
//! Prefer [`gpu_struct!`](crate::gpu_struct), which leaves no second copy to check.

/// The members (name, byte offset) and size of a WGSL struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WgslStruct {
    pub size: u32,
    pub members: Vec<(String, u32)>,
}

/// Reads struct `name` from WGSL `source` (imports already resolved).
pub fn wgsl_struct(source: &str, name: &str) -> Result<WgslStruct, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| format!("layout of the module: {e}"))?;
    module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .and_then(|(handle, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, .. } => Some(WgslStruct {
                size: layouter[handle].size,
                members: members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                    .collect(),
            }),
            _ => None,
        })
        .ok_or_else(|| format!("no struct `{name}` in the shader"))
}

/// The value of module-scope constant `name` (a `u32` or `i32` literal) in WGSL `source`, so
/// numbers shared with Rust (enum codes, sizes) can be checked instead of kept by hand.
pub fn wgsl_integer_constant(source: &str, name: &str) -> Result<i64, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let (_, constant) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .ok_or_else(|| format!("no constant `{name}` in the shader"))?;
    match module.global_expressions[constant.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => Ok(i64::from(v)),
        naga::Expression::Literal(naga::Literal::I32(v)) => Ok(i64::from(v)),
        ref other => Err(format!("`{name}` is not an integer literal: {other:?}")),
    }
}

/// The `@workgroup_size` of compute entry point `entry` in WGSL `source`, so a dispatch written
/// in Rust can be checked against the shader.
pub fn wgsl_workgroup_size(source: &str, entry: &str) -> Result<[u32; 3], String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    module
        .entry_points
        .iter()
        .find(|e| e.name == entry && e.stage == naga::ShaderStage::Compute)
        .map(|e| e.workgroup_size)
        .ok_or_else(|| format!("no compute entry point `{entry}` in the shader"))
}

/// The WGSL values of a choice parameter's options (see [`param_choice!`](crate::param_choice)),
/// read from the shader that switches on them: option `Pcf3x3` of prefix `FILTER` is constant
/// `FILTER_PCF3X3`. The numbers live only in the shader; a missing or repeated constant, or
/// one that is not a `u32` literal, is an error when the technique builds its pipelines.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChoiceCodes(Vec<u32>);

impl ChoiceCodes {
    /// Reads `{prefix}_{NAME}` for every name of `names` (a choice's `NAMES`) from WGSL `source`
    /// (a composed module).
    pub fn read(source: &str, prefix: &str, names: &[&str]) -> Result<ChoiceCodes, String> {
        let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
        let mut codes = Vec::with_capacity(names.len());
        for name in names {
            let constant_name = format!("{prefix}_{}", name.to_uppercase());
            let (_, constant) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(constant_name.as_str()))
                .ok_or_else(|| format!("option `{name}` has no constant `{constant_name}`"))?;
            let code = match module.global_expressions[constant.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                _ => return Err(format!("`{constant_name}` is not a u32 literal")),
            };
            if codes.contains(&code) {
                return Err(format!("`{constant_name}` repeats the value {code}"));
            }
            codes.push(code);
        }
        Ok(ChoiceCodes(codes))
    }

    /// The value of the option at `index` (the choice's `index()`).
    pub fn code(&self, index: usize) -> u32 {
        self.0[index]
    }
}

/// How the Rust size may relate to the WGSL size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SizeRule {
    /// The same size (arrays of the struct, storage buffers).
    Equal,
    /// The Rust struct is padded to a larger slot (uniforms at dynamic offsets).
    AtLeast,
}

/// [`check_mirror`] against struct `name` of the built-in shader `shader` (a path under
/// `shaders/`, imports resolved), with `mirror` as [`mirror_fields!`](crate::mirror_fields)
/// gives it.
pub fn check_embedded_mirror(
    shader: &str,
    name: &str,
    mirror: (usize, Vec<(&str, usize)>),
    rule: SizeRule,
) -> Result<(), String> {
    let composed = crate::ShaderLibrary::embedded()
        .compose(shader)
        .map_err(|e| format!("{shader}: {e}"))?;
    let (size, fields) = mirror;
    check_mirror(&composed.source, name, size, &fields, rule).map_err(|e| format!("{shader}: {e}"))
}

/// Compares the Rust layout (`size`, and `fields` as (WGSL member name, Rust offset)) with
/// WGSL struct `name` in `source`: every member must be at the same offset, members starting
/// with `_` (padding) may be left out, and the sizes must follow `rule`.
pub fn check_mirror(
    source: &str,
    name: &str,
    size: usize,
    fields: &[(&str, usize)],
    rule: SizeRule,
) -> Result<(), String> {
    let wgsl = wgsl_struct(source, name)?;
    let mut problems = Vec::new();
    for (member, offset) in &wgsl.members {
        match fields.iter().find(|(f, _)| f == member) {
            Some((_, rust)) if *rust != *offset as usize => problems.push(format!(
                "`{member}` is at {offset} in WGSL and {rust} in Rust"
            )),
            None if !member.starts_with('_') => {
                problems.push(format!("`{member}` has no Rust field"))
            }
            _ => {}
        }
    }
    for (field, _) in fields {
        if !wgsl.members.iter().any(|(m, _)| m == field) {
            problems.push(format!("Rust field `{field}` is not in WGSL"));
        }
    }
    let size_ok = match rule {
        SizeRule::Equal => size == wgsl.size as usize,
        SizeRule::AtLeast => size >= wgsl.size as usize,
    };
    if !size_ok {
        problems.push(format!(
            "size {size} in Rust, {} in WGSL ({rule:?})",
            wgsl.size
        ));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("`{name}`: {}", problems.join("; ")))
    }
}

/// `(size_of::<T>(), [(member, offset_of!(T, field))...])` for [`check_mirror`]:
/// `mirror_fields!(Pass { light: 0, darkness: 1 })` maps WGSL members to Rust fields (a
/// member alone means a field of the same name).
#[macro_export]
macro_rules! mirror_fields {
    ($ty:ty { $($member:ident $(: $field:tt)?),* $(,)? }) => {
        (
            ::std::mem::size_of::<$ty>(),
            vec![$((
                stringify!($member),
                $crate::mirror_fields!(@offset $ty, $member $(, $field)?),
            )),*],
        )
    };
    (@offset $ty:ty, $member:ident) => { ::std::mem::offset_of!($ty, $member) };
    (@offset $ty:ty, $member:ident, $field:tt) => { ::std::mem::offset_of!($ty, $field) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choice_codes_come_from_the_shader() {
        let source = "const MODE_A: u32 = 3u;\nconst MODE_LONG2X2: u32 = 0u;\n";
        let codes = ChoiceCodes::read(source, "MODE", &["A", "Long2x2"]).unwrap();
        assert_eq!((codes.code(0), codes.code(1)), (3, 0));
        let missing = ChoiceCodes::read(source, "MODE", &["A", "B"]).unwrap_err();
        assert!(missing.contains("`MODE_B`"), "{missing}");
        let repeated = "const MODE_A: u32 = 1u;\nconst MODE_B: u32 = 1u;\n";
        let error = ChoiceCodes::read(repeated, "MODE", &["A", "B"]).unwrap_err();
        assert!(error.contains("repeats"), "{error}");
        let signed = "const MODE_A: i32 = 1;\n";
        assert!(ChoiceCodes::read(signed, "MODE", &["A"]).is_err());
    }
    #[repr(C)]
    struct PartialLight {
        position: [f32; 3],
        kind: u32,
        direction: [f32; 3],
    }

    #[test]
    fn embedded_mirrors_name_the_shader_on_failure() {
        let mirror = crate::mirror_fields!(PartialLight {
            position,
            kind,
            direction
        });
        let missing = check_embedded_mirror("nowhere.wgsl", "Light", mirror, SizeRule::Equal);
        assert!(missing.unwrap_err().contains("nowhere.wgsl"));
        let mirror = crate::mirror_fields!(PartialLight {
            position,
            kind,
            direction
        });
        let drifted = check_embedded_mirror(
            "common/frame.wgsl",
            "CameraUniform",
            mirror,
            SizeRule::Equal,
        );
        assert!(drifted.unwrap_err().contains("common/frame.wgsl"));
    }

    #[test]
    fn integer_constants_are_read_from_the_shader() {
        let source = "const A: u32 = 7u;\nconst B: i32 = -3;\nconst C: f32 = 1.0;";
        assert_eq!(wgsl_integer_constant(source, "A"), Ok(7));
        assert_eq!(wgsl_integer_constant(source, "B"), Ok(-3));
        assert!(wgsl_integer_constant(source, "C").is_err());
        assert!(
            wgsl_integer_constant(source, "D")
                .unwrap_err()
                .contains("no constant")
        );
    }

    #[repr(C)]
    struct Drifted {
        a: u32,
        b: [f32; 3],
    }

    #[test]
    fn drift_is_reported_with_the_member_and_both_offsets() {
        let source = "struct S { a: u32, b: vec3<f32> }";
        let (size, fields) = crate::mirror_fields!(Drifted { a, b });
        let err = check_mirror(source, "S", size, &fields, SizeRule::Equal).unwrap_err();
        // vec3<f32> is 16-byte aligned in WGSL, 4 in Rust.
        assert!(err.contains("`b` is at 16 in WGSL and 4 in Rust"), "{err}");
        assert!(err.contains("size 16 in Rust, 32 in WGSL"), "{err}");
        let err = check_mirror(source, "S", size, &fields[..1], SizeRule::AtLeast).unwrap_err();
        assert!(err.contains("`b` has no Rust field"), "{err}");
        let err = check_mirror(source, "T", size, &fields, SizeRule::Equal).unwrap_err();
        assert!(err.contains("no struct `T`"), "{err}");
    }
}
