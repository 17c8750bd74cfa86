//! Parameters the shaders read (`flags(shader)` in [`technique_params!`](crate::technique_params)):
//! their WGSL struct and its byte packing are generated from the declaration, so no struct,
//! padding or field list is written twice. A technique registers the struct as a shader module
//! with [`shader_params_module!`](crate::shader_params_module), imports it in its WGSL and
//! uploads [`TechniqueParams::shader_block`](crate::params::TechniqueParams::shader_block).

/// A field type the shaders can read: one 32-bit word.
pub trait ShaderValue {
    /// The WGSL type of the word.
    const WGSL_TYPE: &'static str;
    /// The value as the word's bits.
    fn word(&self) -> u32;
    /// WGSL constants naming the values (choices: `FIELD_VARIANT`, as
    /// [`ChoiceCodes`](crate::gpu::layout::ChoiceCodes) reads them).
    fn constants(_field: &str) -> Vec<(String, u32)> {
        Vec::new()
    }
}

impl ShaderValue for f32 {
    const WGSL_TYPE: &'static str = "f32";
    fn word(&self) -> u32 {
        self.to_bits()
    }
}

impl ShaderValue for u32 {
    const WGSL_TYPE: &'static str = "u32";
    fn word(&self) -> u32 {
        *self
    }
}

impl ShaderValue for i32 {
    const WGSL_TYPE: &'static str = "i32";
    fn word(&self) -> u32 {
        *self as u32
    }
}

impl ShaderValue for bool {
    const WGSL_TYPE: &'static str = "u32";
    fn word(&self) -> u32 {
        u32::from(*self)
    }
}

/// One `flags(shader)` field: its name, WGSL type and constants. Its name becomes a WGSL
/// member, so it must not be a WGSL reserved word (`filter`, for one): the test that
/// validates every shader fails on a module that uses one.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaderField {
    pub name: &'static str,
    pub wgsl_type: &'static str,
    pub constants: Vec<(String, u32)>,
}

/// The WGSL declaration of struct `name` with `fields`, padded to a multiple of 16 bytes (so
/// it may sit anywhere in a uniform or storage struct), after the fields' constants.
pub fn wgsl_struct(name: &str, fields: &[ShaderField]) -> String {
    let mut out =
        format!("// Generated from the `flags(shader)` parameters of `{name}`; do not edit.\n");
    for field in fields {
        for (constant, value) in &field.constants {
            out += &format!("const {constant}: u32 = {value}u;\n");
        }
    }
    out += &format!("struct {name} {{\n");
    for field in fields {
        out += &format!("    {}: {},\n", field.name, field.wgsl_type);
    }
    for k in fields.len()..padded_words(fields.len()) {
        out += &format!("    _pad{k}: u32,\n");
    }
    out += "}\n";
    out
}

/// Words of a struct of `fields` one-word fields, padded to 16 bytes (at least one word: WGSL
/// has no empty structs).
pub const fn padded_words(fields: usize) -> usize {
    if fields == 0 {
        4
    } else {
        fields.div_ceil(4) * 4
    }
}

/// A generated WGSL module: a parameter struct registered under a shader-library name.
pub struct GeneratedShader {
    /// The name WGSL imports it by (`#import "ssss/params.wgsl"`).
    pub name: &'static str,
    /// Its text.
    pub source: fn() -> String,
}

inventory::collect!(GeneratedShader);

/// The generated module registered as `name`, if any.
pub fn generated_shader(name: &str) -> Option<String> {
    inventory::iter::<GeneratedShader>
        .into_iter()
        .find(|g| g.name == name)
        .map(|g| (g.source)())
}

/// Every generated module's name.
pub fn generated_shader_names() -> Vec<&'static str> {
    inventory::iter::<GeneratedShader>
        .into_iter()
        .map(|g| g.name)
        .collect()
}

/// Registers the `flags(shader)` struct of parameter type `$ty` as shader module `$name`
/// (the WGSL struct is named as the Rust type).
#[macro_export]
macro_rules! shader_params_module {
    ($name:literal, $ty:ident) => {
        $crate::link_anchor!("shader params");
        $crate::inventory::submit! {
            $crate::params::shader::GeneratedShader {
                name: $name,
                source: || {
                    $crate::params::shader::wgsl_struct(
                        stringify!($ty),
                        &<$ty as $crate::params::TechniqueParams>::shader_fields(),
                    )
                },
            }
        }
    };
}

/// The constants naming a choice's values, `FIELD_VARIANT` in upper case.
pub fn choice_constants(field: &str, names: &[&str]) -> Vec<(String, u32)> {
    names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            (
                format!("{}_{}", field.to_uppercase(), n.to_uppercase()),
                k as u32,
            )
        })
        .collect()
}
