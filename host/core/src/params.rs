//! Typed technique parameters and their schema.
//!
//! A technique declares its parameters once with [`technique_params!`]: that generates a typed
//! struct and a [`ParamSpec`] per field (range, step and doc text) from which the viewer builds
//! its panels, the CLI validates `--set KEY=VALUE` and settings files are checked (they store
//! [`ParamValues`]). Fields flagged `rebuild` decide [`TechniqueParams::update`]; groups shared
//! by several techniques (a library's map or filter settings) are declared once and used.
//!
//! ```
//! zoo_host::param_choice! {
//!     /// How the shadow map is filtered.
//!     pub enum Filter { Nearest, Pcf3x3 }
//! }
//! zoo_host::technique_params! {
//!     /// Parameters of an example technique.
//!     pub struct ExampleParams {
//!         /// Shadow-map resolution in texels.
//!         map_size: u32 = 2048, range(256, 8192), step(256);
//!         /// Constant depth bias in depth units (built into the depth pipeline).
//!         bias: f32 = 0.002, range(0.0, 0.1), step(0.0005), flags(rebuild);
//!         /// Cull front faces in the depth pass.
//!         cull_front: bool = false;
//!         /// Filter mode.
//!         filter: Filter = Filter::Pcf3x3;
//!     }
//! }
//! use zoo_host::params::TechniqueParams;
//! let schema = ExampleParams::schema();
//! assert_eq!(schema[0].key, "map_size");
//! let mut values = ExampleParams::default().to_values();
//! values.insert("bias".into(), zoo_host::params::ParamValue::Float(0.01));
//! assert_eq!(ExampleParams::from_values(&values).unwrap().bias, 0.01);
//! // A new bias is built into pipelines: the technique asks for a new instance.
//! let mut live = ExampleParams::default();
//! assert_eq!(live.update(&values).unwrap(), zoo_host::params::ParamUpdate::Rebuild);
//! ```

pub mod shader;

use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};

/// One parameter value, as stored in settings and edited in the UI.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// A boolean switch.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A real number.
    Float(f64),
    /// The name of one choice of an enumeration.
    Choice(String),
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Bool(v) => write!(f, "{v}"),
            ParamValue::Int(v) => write!(f, "{v}"),
            ParamValue::Float(v) => write!(f, "{v}"),
            ParamValue::Choice(v) => write!(f, "{v}"),
        }
    }
}

/// Parameter values keyed by parameter name.
pub type ParamValues = BTreeMap<String, ParamValue>;

/// The type and allowed values of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamKind {
    /// A boolean switch.
    Bool,
    /// An integer in `min..=max`, edited in steps of `step`.
    Int { min: i64, max: i64, step: i64 },
    /// A real number in `min..=max`, edited in steps of `step`.
    Float { min: f64, max: f64, step: f64 },
    /// One of a fixed list of names.
    Choice { options: &'static [&'static str] },
}

/// Schema entry for one parameter: the UI and the settings files are generated from these.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Field name, used in RON settings and `--set KEY=VALUE`.
    pub key: &'static str,
    /// Doc text shown as a tooltip and in `--help` style listings.
    pub doc: &'static str,
    /// Type and range.
    pub kind: ParamKind,
    /// Default value.
    pub default: ParamValue,
}

/// A parameter that could not be set.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// No parameter of that name exists.
    #[error("unknown parameter `{key}` (known: {known})")]
    Unknown { key: String, known: String },
    /// The value is outside the declared range.
    #[error("parameter `{key}` = {value} is out of range {min}..={max}")]
    OutOfRange {
        key: String,
        value: String,
        min: String,
        max: String,
    },
    /// The value has the wrong type or does not parse.
    #[error("parameter `{key}`: {message}")]
    Invalid { key: String, message: String },
}

impl ParamSpec {
    /// Parses `text` (from `--set KEY=VALUE`) into a value of this parameter's type and checks
    /// its range. Out-of-range values are rejected, not clamped.
    pub fn parse(&self, text: &str) -> Result<ParamValue, ParamError> {
        let text = text.trim();
        let invalid = |message: String| ParamError::Invalid {
            key: self.key.to_string(),
            message,
        };
        let value = match &self.kind {
            ParamKind::Bool => match text {
                "true" | "on" | "1" | "yes" => ParamValue::Bool(true),
                "false" | "off" | "0" | "no" => ParamValue::Bool(false),
                _ => return Err(invalid(format!("expected true or false, got `{text}`"))),
            },
            ParamKind::Int { .. } => ParamValue::Int(
                text.parse()
                    .map_err(|_| invalid(format!("expected an integer, got `{text}`")))?,
            ),
            ParamKind::Float { .. } => ParamValue::Float(
                text.parse()
                    .map_err(|_| invalid(format!("expected a number, got `{text}`")))?,
            ),
            ParamKind::Choice { options } => {
                match options.iter().find(|o| o.eq_ignore_ascii_case(text)) {
                    Some(o) => ParamValue::Choice((*o).to_string()),
                    None => {
                        return Err(invalid(format!(
                            "expected one of {}, got `{text}`",
                            options.join(", ")
                        )));
                    }
                }
            }
        };
        self.check(&value)?;
        Ok(value)
    }

    /// Checks the type and range of `value`.
    pub fn check(&self, value: &ParamValue) -> Result<(), ParamError> {
        let out_of_range = |min: String, max: String| ParamError::OutOfRange {
            key: self.key.to_string(),
            value: value.to_string(),
            min,
            max,
        };
        let wrong_type = |expected: &str| ParamError::Invalid {
            key: self.key.to_string(),
            message: format!("expected {expected}, got `{value}`"),
        };
        match (&self.kind, value) {
            (ParamKind::Bool, ParamValue::Bool(_)) => Ok(()),
            (ParamKind::Int { min, max, .. }, ParamValue::Int(v)) => {
                if v < min || v > max {
                    Err(out_of_range(min.to_string(), max.to_string()))
                } else {
                    Ok(())
                }
            }
            (ParamKind::Float { min, max, .. }, ParamValue::Float(v)) => {
                if !v.is_finite() || v < min || v > max {
                    Err(out_of_range(min.to_string(), max.to_string()))
                } else {
                    Ok(())
                }
            }
            (ParamKind::Float { .. }, ParamValue::Int(v)) => {
                self.check(&ParamValue::Float(*v as f64))
            }
            (ParamKind::Choice { options }, ParamValue::Choice(c)) => {
                if options.contains(&c.as_str()) {
                    Ok(())
                } else {
                    Err(ParamError::Invalid {
                        key: self.key.to_string(),
                        message: format!("expected one of {}, got `{c}`", options.join(", ")),
                    })
                }
            }
            (ParamKind::Bool, _) => Err(wrong_type("true or false")),
            (ParamKind::Int { .. }, _) => Err(wrong_type("an integer")),
            (ParamKind::Float { .. }, _) => Err(wrong_type("a number")),
            (ParamKind::Choice { .. }, _) => Err(wrong_type("a choice name")),
        }
    }

    /// Returns `value` moved into range (what a slider does); wrong types give the default.
    pub fn clamp(&self, value: &ParamValue) -> ParamValue {
        match (&self.kind, value) {
            (ParamKind::Int { min, max, .. }, ParamValue::Int(v)) => {
                ParamValue::Int((*v).clamp(*min, *max))
            }
            (ParamKind::Float { min, max, .. }, ParamValue::Float(v)) if v.is_finite() => {
                ParamValue::Float(v.clamp(*min, *max))
            }
            (ParamKind::Float { min, max, .. }, ParamValue::Int(v)) => {
                ParamValue::Float((*v as f64).clamp(*min, *max))
            }
            _ if self.check(value).is_ok() => value.clone(),
            _ => self.default.clone(),
        }
    }
}

/// Finds the spec of `key` in `schema`, or an error listing the known keys.
pub fn find_spec<'a>(schema: &'a [ParamSpec], key: &str) -> Result<&'a ParamSpec, ParamError> {
    schema
        .iter()
        .find(|s| s.key == key)
        .ok_or_else(|| ParamError::Unknown {
            key: key.to_string(),
            known: if schema.is_empty() {
                "none".to_string()
            } else {
                schema.iter().map(|s| s.key).collect::<Vec<_>>().join(", ")
            },
        })
}

/// Default values of every parameter in `schema`.
pub fn defaults(schema: &[ParamSpec]) -> ParamValues {
    schema
        .iter()
        .map(|s| (s.key.to_string(), s.default.clone()))
        .collect()
}

/// Applies `KEY=VALUE` assignments to `values`, validating each against `schema`.
pub fn apply_assignments(
    schema: &[ParamSpec],
    values: &mut ParamValues,
    assignments: &[(String, String)],
) -> Result<(), ParamError> {
    for (key, text) in assignments {
        let spec = find_spec(schema, key)?;
        values.insert(key.clone(), spec.parse(text)?);
    }
    Ok(())
}

/// A field type usable in [`technique_params!`].
pub trait ParamType: Sized {
    /// The schema kind for this type, given the declared range and step.
    fn kind(range: Option<(f64, f64)>, step: Option<f64>) -> ParamKind;
    /// Converts to the generic value.
    fn to_value(&self) -> ParamValue;
    /// Converts from the generic value (already range-checked).
    fn from_value(value: &ParamValue) -> Option<Self>;
}

impl ParamType for bool {
    fn kind(_: Option<(f64, f64)>, _: Option<f64>) -> ParamKind {
        ParamKind::Bool
    }
    fn to_value(&self) -> ParamValue {
        ParamValue::Bool(*self)
    }
    fn from_value(value: &ParamValue) -> Option<Self> {
        match value {
            ParamValue::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

impl ParamType for f32 {
    fn kind(range: Option<(f64, f64)>, step: Option<f64>) -> ParamKind {
        let (min, max) = range.unwrap_or((f32::MIN as f64, f32::MAX as f64));
        ParamKind::Float {
            min,
            max,
            step: step.unwrap_or((max - min) / 100.0),
        }
    }
    fn to_value(&self) -> ParamValue {
        // Round-trip through the shortest decimal so 0.1f32 shows as 0.1, not 0.10000000149.
        ParamValue::Float(self.to_string().parse().unwrap_or(*self as f64))
    }
    fn from_value(value: &ParamValue) -> Option<Self> {
        match value {
            ParamValue::Float(v) => Some(*v as f32),
            ParamValue::Int(v) => Some(*v as f32),
            _ => None,
        }
    }
}

macro_rules! int_param_type {
    ($($t:ty),*) => {$(
        impl ParamType for $t {
            fn kind(range: Option<(f64, f64)>, step: Option<f64>) -> ParamKind {
                let (min, max) = range.unwrap_or((<$t>::MIN as f64, <$t>::MAX as f64));
                ParamKind::Int {
                    min: min as i64,
                    max: max as i64,
                    step: step.unwrap_or(1.0).max(1.0) as i64,
                }
            }
            fn to_value(&self) -> ParamValue {
                ParamValue::Int(*self as i64)
            }
            fn from_value(value: &ParamValue) -> Option<Self> {
                match value {
                    ParamValue::Int(v) => <$t>::try_from(*v).ok(),
                    _ => None,
                }
            }
        }
    )*};
}
int_param_type!(u32, i32);

/// What a technique did with new parameter values (see [`TechniqueParams::update`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamUpdate {
    /// Taken over by the live instance; the next `prepare` sees `changes.params`.
    Applied,
    /// They change resources or pipelines the instance cannot adjust: the host creates a new
    /// instance with them.
    Rebuild,
}

/// A parameter struct generated by [`technique_params!`].
pub trait TechniqueParams: Default + Clone {
    /// One spec per field: the groups' first, then the struct's own, in declaration order.
    /// A key declared both in a group and by the struct is a mistake the macro cannot see
    /// (the workspace tests check that every technique's keys are unique).
    fn schema() -> Vec<ParamSpec>;
    /// The generic form of these values.
    fn to_values(&self) -> ParamValues;
    /// Builds the struct from generic values; missing keys take their defaults, unknown keys
    /// and out-of-range values are errors.
    fn from_values(values: &ParamValues) -> Result<Self, ParamError>;
    /// Whether going from `before` to these values changes a field declared
    /// `flags(rebuild)` (one built into pipelines or resources).
    fn rebuilds_from(&self, before: &Self) -> bool;
    /// How many fields are declared `flags(shader)` (groups' first).
    const SHADER_FIELDS: usize;
    /// The `flags(shader)` fields, in the order of their words.
    fn shader_fields() -> Vec<shader::ShaderField>;
    /// The `flags(shader)` values, one word each, unpadded.
    fn shader_values(&self) -> Vec<u32>;

    /// The `flags(shader)` values as the generated WGSL struct holds them (padded to 16
    /// bytes): `N` is `shader::padded_words(Self::SHADER_FIELDS)`, the struct's size in words.
    fn shader_block<const N: usize>(&self) -> [u32; N] {
        let mut block = [0; N];
        let values = self.shader_values();
        assert_eq!(
            N,
            shader::padded_words(values.len()),
            "a block of {N} words for {} shader fields",
            values.len()
        );
        block[..values.len()].copy_from_slice(&values);
        block
    }

    /// Takes over `values` unless they change a `flags(rebuild)` field, which asks the host
    /// for a new instance instead (this one keeps its values).
    fn update(&mut self, values: &ParamValues) -> Result<ParamUpdate, ParamError> {
        let next = Self::from_values(values)?;
        if next.rebuilds_from(self) {
            return Ok(ParamUpdate::Rebuild);
        }
        *self = next;
        Ok(ParamUpdate::Applied)
    }
}

/// Declares an enumeration usable as a choice parameter.
#[macro_export]
macro_rules! param_choice {
    ($(#[doc = $doc:literal])* $vis:vis enum $name:ident { $($variant:ident),+ $(,)? }) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, $crate::serde::Serialize, $crate::serde::Deserialize)]
        #[serde(crate = "zoo_host::serde")]
        $vis enum $name { $($variant),+ }

        impl $name {
            /// Every variant's name, in declaration order.
            pub const NAMES: &'static [&'static str] = &[$(stringify!($variant)),+];
            /// This variant's name.
            pub fn name(self) -> &'static str {
                match self { $($name::$variant => stringify!($variant)),+ }
            }
            /// This variant's position in [`Self::NAMES`].
            pub fn index(self) -> usize {
                Self::NAMES.iter().position(|n| *n == self.name()).expect("every variant is named")
            }
        }

        impl $crate::params::shader::ShaderValue for $name {
            const WGSL_TYPE: &'static str = "u32";
            fn word(&self) -> u32 {
                self.index() as u32
            }
            fn constants(field: &str) -> Vec<(String, u32)> {
                $crate::params::shader::choice_constants(field, Self::NAMES)
            }
        }

        impl $crate::params::ParamType for $name {
            fn kind(_: Option<(f64, f64)>, _: Option<f64>) -> $crate::params::ParamKind {
                $crate::params::ParamKind::Choice { options: Self::NAMES }
            }
            fn to_value(&self) -> $crate::params::ParamValue {
                $crate::params::ParamValue::Choice(self.name().to_string())
            }
            fn from_value(value: &$crate::params::ParamValue) -> Option<Self> {
                match value {
                    $($crate::params::ParamValue::Choice(c) if c == stringify!($variant) => Some($name::$variant),)+
                    _ => None,
                }
            }
        }
    };
}

/// Declares a technique's parameter struct together with its schema.
///
/// Each field reads `/// doc` `name: Type = default, range(min, max), step(s), flags(...);`
/// where range and step are optional (they apply to numbers) and so are the flags: `rebuild`
/// marks a field built into pipelines or resources, so that changing it makes
/// [`TechniqueParams::update`] ask for a new instance; `shader` puts it in the struct the
/// shaders read (see [`shader`]). Shared groups of parameters (a struct
/// declared with this macro, such as a library's map or filter settings) come first, as
/// `use name: Group;`: their keys join this struct's schema as if declared here. See the
/// [module docs](crate::params) for an example.
#[macro_export]
macro_rules! technique_params {
    (
        $(#[doc = $doc:literal])*
        $vis:vis struct $name:ident {
            $(use $group:ident : $gty:ty;)*
            $(
                $(#[doc = $fdoc:literal])+
                $field:ident : $ty:ty = $default:expr
                $(, range($min:expr, $max:expr))?
                $(, step($step:expr))?
                $(, flags($($flag:ident),+))?
                ;
            )*
        }
    ) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, PartialEq)]
        $vis struct $name {
            $(
                #[doc = concat!("Shared parameters (`", stringify!($gty), "`).")]
                pub $group: $gty,
            )*
            $( $(#[doc = $fdoc])+ pub $field: $ty, )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self {
                    $($group: <$gty as Default>::default(),)*
                    $($field: $default,)*
                }
            }
        }

        impl $crate::params::TechniqueParams for $name {
            // Groups extend and fields push as declared, so no `vec![]` fits every struct.
            #[allow(clippy::vec_init_then_push)]
            fn schema() -> Vec<$crate::params::ParamSpec> {
                // Built once: the viewer asks every frame, and the doc texts are leaked.
                static SCHEMA: ::std::sync::OnceLock<Vec<$crate::params::ParamSpec>> =
                    ::std::sync::OnceLock::new();
                SCHEMA.get_or_init(|| {
                    let defaults = Self::default();
                    let mut schema = Vec::new();
                    $(schema.extend(<$gty as $crate::params::TechniqueParams>::schema());)*
                    $(schema.push($crate::params::ParamSpec {
                        key: stringify!($field),
                        doc: $crate::params::join_doc(&[$($fdoc),+]),
                        kind: <$ty as $crate::params::ParamType>::kind(
                            None $(.or(Some(($min as f64, $max as f64))))?,
                            None $(.or(Some($step as f64)))?,
                        ),
                        default: $crate::params::ParamType::to_value(&defaults.$field),
                    });)*
                    schema
                }).clone()
            }

            fn to_values(&self) -> $crate::params::ParamValues {
                let mut values = $crate::params::ParamValues::new();
                $(values.extend($crate::params::TechniqueParams::to_values(&self.$group));)*
                $(values.insert(
                    stringify!($field).to_string(),
                    $crate::params::ParamType::to_value(&self.$field),
                );)*
                values
            }

            fn from_values(values: &$crate::params::ParamValues) -> Result<Self, $crate::params::ParamError> {
                let schema = Self::schema();
                for (key, value) in values {
                    $crate::params::find_spec(&schema, key)?.check(value)?;
                }
                let mut out = Self::default();
                $(
                    out.$group = <$gty as $crate::params::TechniqueParams>::from_values(
                        &$crate::params::values_of(
                            &<$gty as $crate::params::TechniqueParams>::schema(),
                            values,
                        ),
                    )?;
                )*
                $(
                    if let Some(value) = values.get(stringify!($field)) {
                        out.$field = $crate::params::ParamType::from_value(value).ok_or_else(|| {
                            $crate::params::ParamError::Invalid {
                                key: stringify!($field).to_string(),
                                message: format!("cannot convert `{value}`"),
                            }
                        })?;
                    }
                )*
                Ok(out)
            }

            const SHADER_FIELDS: usize = 0
                $(+ <$gty as $crate::params::TechniqueParams>::SHADER_FIELDS)*
                $(+ $crate::__param_shader_count!($($($flag)+)?))*;

            // Groups extend and fields push as declared, so no `vec![]` fits every struct.
            #[allow(clippy::vec_init_then_push)]
            fn shader_fields() -> Vec<$crate::params::shader::ShaderField> {
                let mut fields = Vec::new();
                $(fields.extend(<$gty as $crate::params::TechniqueParams>::shader_fields());)*
                $($crate::__param_if_shader!((
                    fields.push($crate::params::shader::ShaderField {
                        name: stringify!($field),
                        wgsl_type: <$ty as $crate::params::shader::ShaderValue>::WGSL_TYPE,
                        constants: <$ty as $crate::params::shader::ShaderValue>::constants(
                            stringify!($field),
                        ),
                    });
                ); $($($flag)+)?);)*
                fields
            }

            // Groups extend and fields push as declared, so no `vec![]` fits every struct.
            #[allow(clippy::vec_init_then_push)]
            fn shader_values(&self) -> Vec<u32> {
                let mut values = Vec::new();
                $(values.extend($crate::params::TechniqueParams::shader_values(&self.$group));)*
                $($crate::__param_if_shader!((
                    values.push($crate::params::shader::ShaderValue::word(&self.$field));
                ); $($($flag)+)?);)*
                values
            }

            fn rebuilds_from(&self, before: &Self) -> bool {
                $($($($crate::__param_known_flag!($flag);)+)?)*
                let changed: &[bool] = &[
                    $($crate::params::TechniqueParams::rebuilds_from(&self.$group, &before.$group),)*
                    $($crate::__param_rebuilds!(self.$field, before.$field; $($($flag)+)?),)*
                ];
                changed.contains(&true)
            }
        }
    };
}

/// The entries of `values` whose keys `schema` declares (a group's share of a struct's values).
pub fn values_of(schema: &[ParamSpec], values: &ParamValues) -> ParamValues {
    values
        .iter()
        .filter(|(key, _)| schema.iter().any(|s| s.key == key.as_str()))
        .map(|(key, value)| (key.clone(), value.clone()))
        .collect()
}

/// Rejects a parameter flag other than the known ones (used by [`technique_params!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __param_known_flag {
    (rebuild) => {};
    (shader) => {};
    ($other:ident) => {
        compile_error!(concat!(
            "unknown parameter flag `",
            stringify!($other),
            "` (known: rebuild, shader)"
        ));
    };
}

/// 1 for a field flagged `shader`, else 0 (used by [`technique_params!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __param_shader_count {
    () => {
        0
    };
    (shader $($rest:ident)*) => {
        1
    };
    ($other:ident $($rest:ident)*) => {
        $crate::__param_shader_count!($($rest)*)
    };
}

/// The wrapped statements for a field flagged `shader`, else nothing (used by
/// [`technique_params!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __param_if_shader {
    (($($then:tt)*);) => {};
    (($($then:tt)*); shader $($rest:ident)*) => {
        $($then)*
    };
    (($($then:tt)*); $other:ident $($rest:ident)*) => {
        $crate::__param_if_shader!(($($then)*); $($rest)*)
    };
}

/// Whether a field flagged with the given flags changed and needs a rebuild (used by
/// [`technique_params!`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __param_rebuilds {
    ($now:expr, $before:expr;) => {
        false
    };
    ($now:expr, $before:expr; rebuild $($rest:ident)*) => {
        $now != $before
    };
    ($now:expr, $before:expr; $other:ident $($rest:ident)*) => {
        $crate::__param_rebuilds!($now, $before; $($rest)*)
    };
}

/// Joins doc-comment lines into one trimmed string (used by [`technique_params!`]).
pub fn join_doc(lines: &[&'static str]) -> &'static str {
    let text = lines.iter().map(|l| l.trim()).collect::<Vec<_>>().join(" ");
    // Each struct's schema is built once per run (`technique_params!` keeps it); leaking keeps
    // `ParamSpec` `'static`.
    Box::leak(text.into_boxed_str())
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::param_choice! {
        /// Test choice.
        pub enum Mode { Fast, Exact }
    }

    crate::technique_params! {
        /// Test parameters.
        pub struct TestParams {
            /// Map size.
            size: u32 = 1024, range(256, 8192), step(256);
            /// Bias.
            bias: f32 = 0.5, range(0.0, 1.0), flags(rebuild, shader);
            /// Switch.
            on: bool = true, flags(shader);
            /// Mode.
            mode: Mode = Mode::Exact, flags(shader);
        }
    }

    #[test]
    fn schema_matches_declaration() {
        let schema = TestParams::schema();
        assert_eq!(
            schema.iter().map(|s| s.key).collect::<Vec<_>>(),
            ["size", "bias", "on", "mode"]
        );
        assert_eq!(
            schema[0].kind,
            ParamKind::Int {
                min: 256,
                max: 8192,
                step: 256
            }
        );
        assert_eq!(schema[0].doc, "Map size.");
        assert_eq!(schema[3].default, ParamValue::Choice("Exact".into()));
        assert_eq!((Mode::Fast.index(), Mode::Exact.index()), (0, 1));
        assert_eq!(Mode::NAMES[Mode::Exact.index()], Mode::Exact.name());
    }

    #[test]
    fn schema_is_built_once() {
        // A schema built per call leaks its doc texts: the viewer asks every frame.
        let (first, second) = (TestParams::schema(), TestParams::schema());
        for (a, b) in first.iter().zip(&second) {
            assert!(std::ptr::eq(a.doc, b.doc), "`{}` doc built twice", a.key);
        }
    }

    #[test]
    fn assignments_are_validated() {
        let schema = TestParams::schema();
        let mut values = defaults(&schema);
        apply_assignments(
            &schema,
            &mut values,
            &[
                ("size".into(), "4096".into()),
                ("mode".into(), "fast".into()),
            ],
        )
        .unwrap();
        let p = TestParams::from_values(&values).unwrap();
        assert_eq!(p.size, 4096);
        assert_eq!(p.mode, Mode::Fast);

        let err = apply_assignments(&schema, &mut values, &[("size".into(), "99999".into())])
            .unwrap_err();
        assert!(err.to_string().contains("out of range 256..=8192"), "{err}");
        let err =
            apply_assignments(&schema, &mut values, &[("nope".into(), "1".into())]).unwrap_err();
        assert!(
            err.to_string().contains("unknown parameter `nope`"),
            "{err}"
        );
        let err =
            apply_assignments(&schema, &mut values, &[("on".into(), "maybe".into())]).unwrap_err();
        assert!(err.to_string().contains("expected true or false"), "{err}");
    }

    #[test]
    fn only_rebuild_fields_ask_for_a_new_instance() {
        let mut live = TestParams::default();
        let mut values = live.to_values();
        values.insert("size".into(), ParamValue::Int(512));
        assert_eq!(live.update(&values).unwrap(), ParamUpdate::Applied);
        assert_eq!(live.size, 512, "taken over");
        values.insert("bias".into(), ParamValue::Float(0.75));
        assert_eq!(live.update(&values).unwrap(), ParamUpdate::Rebuild);
        assert_eq!(live.bias, 0.5, "a rebuild leaves the live values");
        values.insert("bias".into(), ParamValue::Float(7.0));
        assert!(live.update(&values).is_err(), "out of range");
    }

    #[test]
    fn clamp_moves_values_into_range() {
        let schema = TestParams::schema();
        assert_eq!(
            schema[1].clamp(&ParamValue::Float(3.0)),
            ParamValue::Float(1.0)
        );
        assert_eq!(schema[0].clamp(&ParamValue::Int(1)), ParamValue::Int(256));
        assert_eq!(
            schema[3].clamp(&ParamValue::Choice("bogus".into())),
            ParamValue::Choice("Exact".into())
        );
    }

    crate::technique_params! {
        /// Test parameters with a shared group.
        pub struct Grouped {
            use shared: TestParams;
            /// Own value.
            own: u32 = 3, range(0, 9), flags(rebuild);
        }
    }

    #[test]
    fn groups_join_the_schema_values_and_rebuild_rule() {
        let keys: Vec<_> = Grouped::schema().iter().map(|s| s.key).collect();
        assert_eq!(keys, ["size", "bias", "on", "mode", "own"]);
        let mut values = Grouped::default().to_values();
        assert_eq!(values.len(), 5);
        values.insert("size".into(), ParamValue::Int(2048));
        values.insert("own".into(), ParamValue::Int(4));
        let p = Grouped::from_values(&values).unwrap();
        assert_eq!((p.shared.size, p.own), (2048, 4));
        let err =
            Grouped::from_values(&[("sise".to_string(), ParamValue::Int(1))].into()).unwrap_err();
        assert!(
            err.to_string().contains("unknown parameter `sise`"),
            "{err}"
        );
        let err =
            Grouped::from_values(&[("size".to_string(), ParamValue::Int(1))].into()).unwrap_err();
        assert!(
            err.to_string().contains("out of range"),
            "a group's ranges hold: {err}"
        );
        let mut live = Grouped::default();
        values.insert("own".into(), ParamValue::Int(3));
        assert_eq!(live.update(&values).unwrap(), ParamUpdate::Applied);
        values.insert("bias".into(), ParamValue::Float(0.9));
        assert_eq!(
            live.update(&values).unwrap(),
            ParamUpdate::Rebuild,
            "a group's rebuild fields rebuild"
        );
    }

    #[test]
    fn shader_fields_make_a_padded_wgsl_struct_and_its_words() {
        assert_eq!(TestParams::SHADER_FIELDS, 3);
        assert_eq!(Grouped::SHADER_FIELDS, 3, "a group's shader fields count");
        let text = shader::wgsl_struct("TestParams", &TestParams::shader_fields());
        assert!(
            text.contains("const MODE_FAST: u32 = 0u;\nconst MODE_EXACT: u32 = 1u;"),
            "{text}"
        );
        assert!(
            text.contains("bias: f32,\n    on: u32,\n    mode: u32,\n    _pad3: u32,\n}"),
            "{text}"
        );
        let p = TestParams {
            bias: 0.25,
            on: false,
            ..TestParams::default()
        };
        let block: [u32; 4] = p.shader_block();
        assert_eq!(block, [0.25f32.to_bits(), 0, 1, 0]);
        // The struct is valid WGSL, 16 bytes in uniform and storage buffers.
        let source = format!("{text}\n@group(0) @binding(0) var<uniform> p: TestParams;\n");
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, _) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("TestParams"))
            .unwrap();
        assert_eq!(layouter[handle].size, 16);
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap();
    }

    #[test]
    #[should_panic(expected = "a block of 8 words for 3 shader fields")]
    fn a_block_of_the_wrong_size_is_refused() {
        let _: [u32; 8] = TestParams::default().shader_block();
    }
}
