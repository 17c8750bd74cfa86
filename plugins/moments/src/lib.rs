//! The moment family of filterable shadow maps, beside VSM: exponential shadow maps (Annen et
//! al. 2008), exponential variance shadow maps with two and four moments (Lauritzen and McCool
//! 2008) and Hamburger moment shadow maps (Peters and Klein 2015). Each method is one WGSL file
//! in `shaders/moments/` (what a texel stores, and the visibility the filtered moments give)
//! and one [`Method`] below; maps, fitting, blur and lookup are the shadow-map library's
//! moment maps. The exponents reach the WGSL as generated constants, so changing one rebuilds
//! the passes.

use zoo_host::params::{ParamSpec, TechniqueParams, find_spec};
use zoo_host::prelude::*;
use zoo_shadow_maps::{
    MOMENTS_RG_FORMAT, MOMENTS_RGBA_FORMAT, MomentChoice, MomentMethod, MomentSettings,
    MomentShadows,
};

zoo_host::technique_params! {
    /// Parameters of the moment family (each method shows the ones it reads).
    pub struct MomentParams {
        /// Moment-map resolution in texels per side (clamped to the device and memory budget).
        map_size: u32 = 2048, range(256, 8192), step(256);
        /// Gaussian blur of the moments, in taps on each side (0: bilinear filtering only).
        blur_radius: u32 = 2, range(0, 16), step(1);
        /// Exponent of the positive warp exp(c (z - 1)).
        positive_exponent: f32 = 40.0, range(1.0, 42.0), step(1.0), flags(rebuild);
        /// Exponent of the negative warp exp(c (1 - z)) (EVSM4).
        negative_exponent: f32 = 5.0, range(1.0, 42.0), step(1.0), flags(rebuild);
        /// Smallest variance in squared light-depth units, scaled by each warp's slope (EVSM).
        min_variance: f32 = 0.00001, range(0.0, 0.001), step(0.00001);
        /// Moment bias: the filtered moments move this far towards (0.5, 0.5, 0.5, 0.5)
        /// (MSM).
        moment_bias: f32 = 0.00003, range(0.0, 0.01), step(0.00001);
        /// Light-bleeding reduction: visibility below it becomes 0 and the rest is rescaled.
        bleeding_reduction: f32 = 0.0, range(0.0, 0.95), step(0.05);
        /// Lookups move off the surface by this many map texels along the normal.
        normal_offset: f32 = 1.0, range(0.0, 8.0), step(0.1);
        /// Keep directional maps stable as the camera moves (no shimmering edges).
        stable_fit: bool = true;
    }
}

/// Parameters every method reads.
const COMMON: &[&str] = &[
    "map_size",
    "blur_radius",
    "bleeding_reduction",
    "normal_offset",
    "stable_fit",
];

/// One method of the family.
pub struct Method {
    label: &'static str,
    shader: &'static str,
    /// Stores four moments (else two).
    four: bool,
    /// The method's own parameters, beside [`COMMON`].
    reads: &'static [&'static str],
    /// Its bias, in the units its WGSL reads.
    bias: fn(&MomentParams) -> f32,
}

const ESM: Method = Method {
    label: "ESM",
    shader: "moments/esm.wgsl",
    four: false,
    reads: &["positive_exponent"],
    bias: |_| 0.0,
};
const EVSM2: Method = Method {
    label: "EVSM2",
    shader: "moments/evsm2.wgsl",
    four: false,
    reads: &["positive_exponent", "min_variance"],
    bias: |p| p.min_variance,
};
const EVSM4: Method = Method {
    label: "EVSM4",
    shader: "moments/evsm4.wgsl",
    four: true,
    reads: &["positive_exponent", "negative_exponent", "min_variance"],
    bias: |p| p.min_variance,
};
const MSM: Method = Method {
    label: "MSM",
    shader: "moments/msm.wgsl",
    four: true,
    reads: &["moment_bias"],
    bias: |p| p.moment_bias,
};

impl Method {
    /// The parameters this method reads, in declaration order.
    fn schema(&self) -> Vec<ParamSpec> {
        let reads = |key: &str| COMMON.contains(&key) || self.reads.contains(&key);
        (MomentParams::schema().into_iter())
            .filter(|spec| reads(spec.key))
            .collect()
    }

    /// Parameters from `values`, which may name only this method's keys.
    fn params(&self, values: &ParamValues) -> TechniqueResult<MomentParams> {
        let schema = self.schema();
        for (key, value) in values {
            find_spec(&schema, key)?.check(value)?;
        }
        Ok(MomentParams::from_values(values)?)
    }

    /// The method's WGSL constants. The maps hold 32-bit floats, so no moment of an exponent
    /// in range overflows: exp(2 * 42) < f32::MAX. The limit is written as its exact decimal
    /// value: browsers reject the shortest form, 3.4028235e38, as above the largest f32.
    fn prelude(p: &MomentParams) -> String {
        format!(
            "const POSITIVE_EXPONENT: f32 = {:?};\nconst NEGATIVE_EXPONENT: f32 = {:?};\nconst MOMENT_LIMIT: f32 = {:.1};\n",
            p.positive_exponent,
            p.negative_exponent,
            f64::from(f32::MAX),
        )
    }

    /// The format of the method's maps.
    fn format(&self) -> wgpu::TextureFormat {
        if self.four {
            MOMENTS_RGBA_FORMAT
        } else {
            MOMENTS_RG_FORMAT
        }
    }
}

/// A moment method with its parameters: its choice of the library's moment maps.
struct MomentShadowing {
    method: &'static Method,
    params: MomentParams,
}

impl MomentChoice for MomentShadowing {
    fn method(&self) -> MomentMethod {
        MomentMethod {
            label: self.method.label,
            shader: self.method.shader,
            prelude: Method::prelude(&self.params),
            format: self.method.format(),
        }
    }

    fn settings(&self) -> MomentSettings {
        let p = &self.params;
        MomentSettings {
            map_size: p.map_size,
            stable_fit: p.stable_fit,
            blur_radius: p.blur_radius,
            normal_offset: p.normal_offset,
            bias: (self.method.bias)(p),
            bleeding_reduction: p.bleeding_reduction,
        }
    }

    fn update(&mut self, values: &ParamValues) -> TechniqueResult<ParamUpdate> {
        // The exponents are WGSL constants of the passes (`flags(rebuild)`).
        let next = self.method.params(values)?;
        if next.rebuilds_from(&self.params) {
            return Ok(ParamUpdate::Rebuild);
        }
        self.params = next;
        Ok(ParamUpdate::Applied)
    }
}

fn create(
    method: &'static Method,
    values: &ParamValues,
) -> TechniqueResult<Box<dyn ShadowTechnique>> {
    let params = method.params(values)?;
    Ok(MomentShadows::boxed(MomentShadowing { method, params }))
}

/// Registers one method as its own technique.
macro_rules! register_method {
    ($method:ident, $id:literal, $name:literal, $description:literal, $source:literal) => {
        zoo_host::register_technique! {
            id: $id,
            name: $name,
            description: $description,
            source: $source,
            readme: include_str!("../README.md"),
            light_kinds: &[LightKind::Directional, LightKind::Point, LightKind::Spot],
            params: || $method.schema(),
            create: |_, values| create(&$method, values),
        }
    };
}

register_method!(
    ESM,
    "esm",
    "Exponential shadow maps",
    "Blurred exp(c z) per light; visibility from the filtered exponential",
    "Annen et al. 2008 (seed 000 section 13.3's family)"
);
register_method!(
    EVSM2,
    "evsm2",
    "Exponential variance shadow maps (2 moments)",
    "Chebyshev's bound on exponentially warped depth: less light bleeding than VSM",
    "Lauritzen and McCool 2008 (seed 000 section 13.3's family)"
);
register_method!(
    EVSM4,
    "evsm4",
    "Exponential variance shadow maps (4 moments)",
    "Positive and negative exponential warps, the tighter Chebyshev bound wins",
    "Lauritzen and McCool 2008 (seed 000 section 13.3's family)"
);
register_method!(
    MSM,
    "msm",
    "Moment shadow maps (Hamburger 4MSM)",
    "Four depth moments; the sharpest bound on the lit fraction any distribution allows",
    "Peters and Klein 2015 (seed 000 section 13.3's family)"
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_method_accepts_only_its_parameters() {
        let mut values = ParamValues::new();
        values.insert(
            "moment_bias".into(),
            zoo_host::params::ParamValue::Float(1e-4),
        );
        assert_eq!(MSM.params(&values).unwrap().moment_bias, 1e-4);
        let err = ESM.params(&values).unwrap_err().to_string();
        assert!(err.contains("unknown parameter `moment_bias`"), "{err}");
        let keys: Vec<_> = EVSM4.schema().iter().map(|s| s.key).collect();
        assert!(keys.contains(&"negative_exponent") && !keys.contains(&"moment_bias"));
    }

    #[test]
    fn exponents_reach_the_shaders_unclamped() {
        let p = MomentParams {
            positive_exponent: 42.0,
            ..MomentParams::default()
        };
        let prelude = Method::prelude(&p);
        assert!(
            prelude.contains("POSITIVE_EXPONENT: f32 = 42.0;"),
            "{prelude}"
        );
        assert!(
            prelude.contains("NEGATIVE_EXPONENT: f32 = 5.0;"),
            "{prelude}"
        );
        // The largest second moment of the largest exponent stays finite in the maps.
        assert!((2.0 * 42.0f32).exp().is_finite());
    }
}
