//! Rendering techniques and scoring them with the reference judge.
//!
//! The reference depends only on the G-buffer (the camera and the scene), so it is computed once
//! per view and every technique rendered from that view is scored against it.

pub mod perceptual;
pub mod shared_references;

use web_time::Instant;

use image::{Rgba, RgbaImage};
use rayon::prelude::*;
use zoo_judge::{
    DEFAULT_AREA_SAMPLES, ErrorClass, LightReference, Metrics, Occluders, Reflectors, SurfacePoint,
    Surfaces, error_class, leak, lit_points, one_bounce, reference_visibility, relative_rmse,
    unlit_by_one_bounce,
};

use crate::gpu::{FrameTimings, PassOwner};
use crate::params::ParamValues;
use crate::render::{GBufferData, RenderError, Renderer, View};
use crate::scene::{Light, LightKind, Scene};

/// The judge's verdict about one view of a scene, shared by every technique.
pub struct SceneReference {
    /// The G-buffer the reference was computed for.
    pub gbuffer: GBufferData,
    /// Reference visibility per light.
    pub lights: Vec<LightReference>,
    /// Shadow-casting triangles traced.
    pub occluder_triangles: usize,
    /// Seconds spent building the BVH and tracing.
    pub seconds: f64,
    /// The one-bounce indirect reference per pixel, once [`Self::indirect`] computed it, with
    /// the samples and lights it was traced for.
    indirect: Option<(u32, Vec<Light>, Vec<glam::Vec3>)>,
    /// The pixels no directly lit surface sees, once [`Self::unlit`] found them, for the
    /// indirect reference they were found with.
    unlit: Option<(u32, Vec<Light>, Vec<bool>)>,
    /// What the indirect reference and the unlit pixels trace, built once for both.
    bounce: Option<BounceScene>,
}

/// The scene as the one-bounce reference traces it: every caster, every reflecting surface
/// and this view's pixel surfaces.
struct BounceScene {
    occluders: Occluders,
    reflectors: Reflectors,
    points: Vec<Option<SurfacePoint>>,
}

/// How much indirect light a technique leaks onto surfaces no directly lit surface sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leak {
    /// Its mean indirect light on those pixels as a fraction of the reference's mean over every
    /// surface pixel (0 where no pixel is unlit or it adds nothing there; infinite where the
    /// reference is black everywhere and it adds light on them).
    pub leak: f64,
    /// The share of surface pixels that no directly lit surface sees.
    pub unlit_share: f64,
}

impl SceneReference {
    /// Renders the G-buffer of `renderer`'s current view and traces the reference for every
    /// light with `samples` area samples per pixel. `progress` is called after each light.
    pub fn compute(
        renderer: &mut Renderer,
        samples: u32,
        mut progress: impl FnMut(usize),
    ) -> Result<SceneReference, RenderError> {
        // Any technique leaves the G-buffer the same; render one frame to fill it.
        renderer.render(&View::Final)?;
        let gbuffer = renderer.read_gbuffer();
        let start = Instant::now();
        let occluders = Occluders::new(renderer.scene());
        let points = surface_points(&gbuffer, &Surfaces::new(renderer.scene()));
        let shared = shared_references::folder()
            .map(|folder| (folder, shared_references::scene_digest(renderer.scene())));
        let lights = renderer
            .lights()
            .iter()
            .enumerate()
            .map(|(i, light)| {
                let r = match &shared {
                    Some((folder, scene)) => shared_references::light_reference(
                        folder,
                        (*scene, &occluders),
                        light,
                        &points,
                        samples,
                    ),
                    None => reference_visibility(&occluders, light, &points, samples),
                };
                progress(i);
                r
            })
            .collect();
        Ok(SceneReference {
            gbuffer,
            lights,
            occluder_triangles: occluders.len(),
            seconds: start.elapsed().as_secs_f64(),
            indirect: None,
            unlit: None,
            bounce: None,
        })
    }

    /// A reference traced elsewhere (on the GPU): `lights` for the G-buffer `gbuffer`, from
    /// `occluder_triangles` casters in `seconds`. The one-bounce reference is traced on the CPU
    /// when asked for.
    pub fn from_traced(
        gbuffer: GBufferData,
        lights: Vec<LightReference>,
        occluder_triangles: usize,
        seconds: f64,
    ) -> SceneReference {
        SceneReference {
            gbuffer,
            lights,
            occluder_triangles,
            seconds,
            indirect: None,
            unlit: None,
            bounce: None,
        }
    }

    /// The one-bounce diffuse reference for this view (irradiance over π per pixel, the
    /// quantity of the indirect target), traced with `samples` rays per pixel when first asked
    /// for with these samples and lights (it costs a BVH of every surface and a shadow ray
    /// per light and hit).
    pub fn indirect(&mut self, scene: &Scene, lights: &[Light], samples: u32) -> &[glam::Vec3] {
        let current = self
            .indirect
            .as_ref()
            .is_some_and(|(s, l, _)| *s == samples && l.as_slice() == lights);
        if !current {
            let start = Instant::now();
            let b = self.bounce_scene(scene);
            let traced = one_bounce(&b.occluders, &b.reflectors, lights, &b.points, samples);
            self.seconds += start.elapsed().as_secs_f64();
            self.indirect = Some((samples, lights.to_vec(), traced));
        }
        &self.indirect.as_ref().expect("computed above").2
    }

    /// The pixels whose surface no directly lit surface sees (their one-bounce light is 0):
    /// the reference is 0 there and none of the points traced as lit from every light is in
    /// view. Found when first asked for with these samples and lights.
    pub fn unlit(&mut self, scene: &Scene, lights: &[Light], samples: u32) -> &[bool] {
        let current = self
            .unlit
            .as_ref()
            .is_some_and(|(s, l, _)| *s == samples && l.as_slice() == lights);
        if !current {
            let reference = self.indirect(scene, lights, samples).to_vec();
            let start = Instant::now();
            let b = self.bounce_scene(scene);
            let lit = lit_points(&b.occluders, &b.reflectors, lights);
            let unlit = unlit_by_one_bounce(&b.reflectors, &lit, &b.points, &reference);
            self.seconds += start.elapsed().as_secs_f64();
            self.unlit = Some((samples, lights.to_vec(), unlit));
        }
        &self.unlit.as_ref().expect("computed above").2
    }

    /// The scene as the one-bounce reference traces it, built on first use (a reference
    /// belongs to one scene: its G-buffer's).
    fn bounce_scene(&mut self, scene: &Scene) -> &BounceScene {
        let gbuffer = &self.gbuffer;
        self.bounce.get_or_insert_with(|| BounceScene {
            occluders: Occluders::new(scene),
            reflectors: Reflectors::new(scene),
            points: surface_points(gbuffer, &Surfaces::new(scene)),
        })
    }

    /// The pixels with a surface.
    pub fn surface_mask(&self) -> Vec<bool> {
        self.gbuffer.positions.iter().map(|p| p.w > 0.5).collect()
    }

    /// Output width and height.
    pub fn size(&self) -> (usize, usize) {
        (self.gbuffer.size.x as usize, self.gbuffer.size.y as usize)
    }
}

/// The G-buffer's surfaces as judge input (`None` on background pixels), each located on the
/// exact triangles of the scene ([`Surfaces::locate`]).
pub fn surface_points(gbuffer: &GBufferData, surfaces: &Surfaces) -> Vec<Option<SurfacePoint>> {
    gbuffer
        .positions
        .par_iter()
        .zip(&gbuffer.normals)
        .map(|(p, n)| {
            (p.w > 0.5 && n.is_finite() && p.is_finite())
                .then(|| surfaces.locate(gbuffer.eye, p.truncate(), n.normalize_or_zero()))
        })
        .collect()
}

/// The score of one technique for one light.
#[derive(Debug, Clone)]
pub struct LightScore {
    pub light: usize,
    pub kind: LightKind,
    /// `None` when the technique does not support this light kind (not scored as wrong).
    pub metrics: Option<Metrics>,
}

/// A technique rendered and judged.
pub struct Judged {
    pub technique: String,
    pub params: ParamValues,
    pub scores: Vec<LightScore>,
    pub timings: FrameTimings,
    /// The technique's summed pass time for the frame.
    pub gpu_ms: f64,
    /// The final image.
    pub image: RgbaImage,
    /// The technique's visibility per light (times the mean of its transmittance colour
    /// where it writes one).
    pub visibility: Vec<Vec<f32>>,
    /// The technique's transmittance colour per light, when it writes one.
    pub transmittance: Vec<Option<Vec<glam::Vec3>>>,
    /// Visibility slots the lights shared (fewer than lights when the technique packs them).
    pub slot_count: u32,
    /// The indirect light it added per pixel, for techniques that add light.
    pub indirect: Option<Vec<glam::Vec3>>,
    /// Whether it treated the scene's alpha-masked casters as opaque (see
    /// [`crate::MaskedCasters`]).
    pub masks_opaque: bool,
    /// What it could not meet in the judged frame ([`crate::ShadowTechnique::warnings`]).
    pub warnings: Vec<String>,
    /// For a technique that adds light, the lights that add nothing to its indirect light, and
    /// why ([`crate::ShadowTechnique::unbounced`]).
    pub unbounced: Vec<(usize, String)>,
}

impl Judged {
    /// Relative RMSE of its indirect light against `reference`'s one-bounce reference
    /// (`None` for techniques that add no light). Traces the reference on first use.
    pub fn indirect_rmse(
        &self,
        reference: &mut SceneReference,
        scene: &Scene,
        lights: &[Light],
        samples: u32,
    ) -> Option<f64> {
        let estimate = self.indirect.as_ref()?;
        let mask = reference.surface_mask();
        let expected = reference.indirect(scene, lights, samples);
        Some(relative_rmse(expected, estimate, &mask))
    }

    /// Its indirect light on the surfaces no directly lit surface sees ([`Leak`]; `None` for
    /// techniques that add no light). Traces the reference and finds those surfaces on first
    /// use.
    pub fn indirect_leak(
        &self,
        reference: &mut SceneReference,
        scene: &Scene,
        lights: &[Light],
        samples: u32,
    ) -> Option<Leak> {
        let estimate = self.indirect.as_ref()?;
        let mask = reference.surface_mask();
        let unlit = reference.unlit(scene, lights, samples).to_vec();
        let expected = reference.indirect(scene, lights, samples);
        let surfaces = mask.iter().filter(|m| **m).count().max(1);
        Some(Leak {
            leak: leak(expected, estimate, &mask, &unlit),
            unlit_share: unlit.iter().filter(|u| **u).count() as f64 / surfaces as f64,
        })
    }
}

/// Switches `renderer` to technique `id` with `params`, renders the current view and scores it
/// against `reference`.
pub fn judge_technique(
    renderer: &mut Renderer,
    reference: &SceneReference,
    id: &str,
    params: &ParamValues,
) -> Result<Judged, RenderError> {
    renderer.set_technique(id, params)?;
    // A first frame lets techniques with temporal state settle; those that accumulate over
    // frames get as many more as they converge in; the last is measured.
    renderer.render(&View::Final)?;
    for _ in 2..renderer.technique_instance().frames_to_converge() {
        renderer.render(&View::Final)?;
    }
    let timings = renderer.render(&View::Final)?;
    let registration = renderer.technique();
    let (width, height) = reference.size();
    let mut scores = Vec::new();
    let mut visibility = Vec::new();
    let mut transmittance = Vec::new();
    for (i, light) in renderer.lights().iter().enumerate() {
        let (v, t) = scored_visibility(renderer, i);
        transmittance.push(t);
        let metrics = registration
            .supports(light.kind)
            .then(|| Metrics::compute(&reference.lights[i], &v, width, height, None));
        scores.push(LightScore {
            light: i,
            kind: light.kind,
            metrics,
        });
        visibility.push(v);
    }
    Ok(Judged {
        technique: id.to_string(),
        params: renderer.technique_params().clone(),
        scores,
        gpu_ms: timings.total(PassOwner::Technique),
        timings,
        image: renderer.read_output(),
        visibility,
        transmittance,
        slot_count: renderer.slots().slot_count(),
        indirect: registration.adds_light.then(|| renderer.read_indirect()),
        masks_opaque: registration.masks_opaque_in(renderer.scene()),
        warnings: renderer.technique_instance().warnings(),
        unbounced: match registration.adds_light {
            true => (renderer.lights().iter().enumerate())
                .filter_map(|(i, l)| Some((i, renderer.technique_instance().unbounced(l)?)))
                .collect(),
            false => Vec::new(),
        },
    })
}

/// What the judge scores of light `light` in `renderer`'s last frame: the technique's
/// visibility, times the mean of its transmittance colour where it writes one (behind
/// translucent casters the light that arrives, as the reference's), and that colour.
pub fn scored_visibility(renderer: &Renderer, light: usize) -> (Vec<f32>, Option<Vec<glam::Vec3>>) {
    let colored = renderer
        .technique_instance()
        .writes_transmittance(renderer.scene());
    let t = colored.then(|| renderer.read_transmittance(light));
    (scored(renderer.read_visibility(light), t.as_deref()), t)
}

/// Visibility as scored: times the mean of the colour kept through translucent casters, where
/// the technique writes it.
pub fn scored(mut visibility: Vec<f32>, transmittance: Option<&[glam::Vec3]>) -> Vec<f32> {
    if let Some(t) = transmittance {
        for (v, t) in visibility.iter_mut().zip(t) {
            *v *= (t.x + t.y + t.z) / 3.0;
        }
    }
    visibility
}

/// The error map of one light: red where the technique shadows a lit pixel, blue where it
/// lights a shadowed one, grey where both agree on shadow, the scene dimmed elsewhere.
pub fn error_map(reference: &LightReference, visibility: &[f32], scene: &RgbaImage) -> RgbaImage {
    let mut out = scene.clone();
    for (i, pixel) in out.pixels_mut().enumerate() {
        *pixel = match error_class(reference, visibility, i) {
            ErrorClass::FalseShadow => Rgba([230, 30, 30, 255]),
            ErrorClass::FalseLit => Rgba([40, 90, 255, 255]),
            ErrorClass::BothShadowed => Rgba([128, 128, 128, 255]),
            ErrorClass::BothLit | ErrorClass::NotContributing => {
                let [r, g, b, _] = pixel.0;
                Rgba([r / 3, g / 3, b / 3, 255])
            }
        };
    }
    out
}

/// The deferred lighting evaluated on the CPU (the mirror of `shaders/host/lighting.wgsl`)
/// from a G-buffer, one visibility per light (for example the reference's) and, for light
/// that a technique adds, the indirect light per pixel, which replaces the scene's ambient as
/// it does on the GPU. Background pixels keep the colour they have in `background`.
pub fn shade_on_cpu(
    renderer: &Renderer,
    gbuffer: &GBufferData,
    visibility: &[&[f32]],
    indirect: Option<&[glam::Vec3]>,
    background: &RgbaImage,
) -> RgbaImage {
    use crate::scene::shading;
    let eye = renderer.camera().position;
    let ambient = match indirect {
        Some(_) => glam::Vec3::ZERO,
        None => renderer.scene().ambient,
    };
    let mut out = background.clone();
    for (i, pixel) in out.pixels_mut().enumerate() {
        let p = gbuffer.positions[i];
        if p.w < 0.5 {
            continue;
        }
        let m = &gbuffer.materials[i];
        let position = p.truncate();
        let view_dir = (eye - position).normalize_or_zero();
        let mut c = ambient * m.albedo;
        if let Some(indirect) = indirect {
            c += indirect[i] * m.albedo;
        }
        for (light, v) in renderer.lights().iter().zip(visibility) {
            if v[i] > 0.0 {
                c += v[i] * shading::direct_light(light, position, gbuffer.normals[i], view_dir, m);
            }
        }
        let srgb = shading::tonemap(c).map(shading::linear_to_srgb) * 255.0;
        let [r, g, b] = srgb.to_array().map(|x| x.round().clamp(0.0, 255.0) as u8);
        *pixel = Rgba([r, g, b, 255]);
    }
    out
}

/// Area samples per pixel used when none are given.
pub const DEFAULT_SAMPLES: u32 = DEFAULT_AREA_SAMPLES;
