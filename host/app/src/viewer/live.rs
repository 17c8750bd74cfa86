//! The live reference: while it is on, the view is judged against visibility traced on the
//! GPU by the GPU judge's tracer (`rt-shadows`, in a renderer of its own) whenever it changes:
//! hard visibility in the frame of the change, then [`RAYS_PER_FRAME`] area rays a pixel and
//! light added each frame up to the GPU judge's [`MAX_SAMPLES`], the technique scored against
//! it each time; a change of technique or parameters is judged against what is traced. Which
//! pixels a light reaches comes from the G-buffer's surfaces ("Judge view" runs the CPU judge,
//! the arbiter, which locates them on the exact triangles). Behind translucent casters a soft
//! light's colour is the last frame's rays' (rt-shadows averages visibility over frames, not
//! colour).

use web_time::Instant;

use zoo_host::glam::Vec3;
use zoo_host::judge::Metrics;
use zoo_host::judging::{error_map, scored_visibility};
use zoo_host::scene::shading::contributes;
use zoo_host::technique::counter;
use zoo_host::{Renderer, View};

use super::judgement::{JudgedView, Judgement};
use crate::gpu_judge::{MAX_SAMPLES, TRACER, light_reference, read_traced, tracer_values};

/// Area rays a pixel and light each frame adds.
pub const RAYS_PER_FRAME: u32 = 4;

/// What the reference depends on: the view without the technique that is judged.
#[derive(Debug, Clone, PartialEq)]
struct TracedView {
    camera: zoo_host::Camera,
    lights: Vec<zoo_host::Light>,
    size: zoo_host::glam::UVec2,
}

impl TracedView {
    fn of(view: &JudgedView) -> TracedView {
        TracedView {
            camera: view.camera,
            lights: view.lights.clone(),
            size: view.size,
        }
    }
}

/// The tracer and what it has traced of the current view.
#[derive(Default)]
pub struct LiveReference {
    tracer: Option<Renderer>,
    /// What the tracer traced (`None` until a trace of it succeeds).
    traced: Option<TracedView>,
    /// What was judged last.
    judged: Option<JudgedView>,
    /// Per light: the pixels it reaches, and the colour fraction of it that arrives there from
    /// its centre.
    contributing: Vec<Vec<bool>>,
    hard: Vec<Vec<Vec3>>,
    /// Per light: the colour fraction of its area that arrives (the hard one until area rays
    /// are traced).
    area: Vec<Vec<Vec3>>,
    /// Area rays a pixel traced for the current view (0: hard visibility only).
    samples: u32,
    /// Tracing time spent on the current view.
    seconds: f64,
}

impl LiveReference {
    /// Area rays a pixel traced so far for the current view.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Traces more of the reference of what `renderer` shows (rendered this frame) and judges
    /// its technique against it: the new judgement, or `None` once the view has all its
    /// samples and nothing judged changed. A change of technique or parameters is judged
    /// against the samples already traced.
    pub fn update(&mut self, renderer: &Renderer) -> anyhow::Result<Option<Judgement>> {
        let view = JudgedView::of(renderer);
        let start = Instant::now();
        if self.traced.as_ref() != Some(&TracedView::of(&view)) {
            self.restart(renderer, &view)?;
        } else if self.samples < MAX_SAMPLES {
            let tracer = self.tracer.as_mut().expect("a view was traced");
            if self.samples == 0 {
                // Parameters only: the tracer keeps its pipelines and hierarchy.
                let frames = MAX_SAMPLES / RAYS_PER_FRAME;
                tracer.set_params(&tracer_values(RAYS_PER_FRAME, frames)?)?;
            }
            tracer.render(&View::Final)?;
            self.samples += RAYS_PER_FRAME;
            self.area = read_traced(tracer);
        } else if self.judged.as_ref() == Some(&view) {
            return Ok(None);
        }
        self.seconds += start.elapsed().as_secs_f64();
        self.judged = Some(view.clone());
        Ok(Some(self.judge(renderer, view)))
    }

    /// Traces the hard visibility of `view` and which pixels each light reaches.
    fn restart(&mut self, renderer: &Renderer, view: &JudgedView) -> anyhow::Result<()> {
        self.traced = None;
        let hard = tracer_values(1, 1)?;
        let tracer = match &mut self.tracer {
            Some(tracer) => {
                tracer.set_params(&hard)?;
                tracer
            }
            empty => {
                let mut tracer = Renderer::with_shaders(
                    renderer.gpu().clone(),
                    renderer.scene().clone(),
                    view.size,
                    renderer.shaders().clone(),
                )?;
                tracer.set_technique(TRACER, &hard)?;
                empty.insert(tracer)
            }
        };
        tracer.set_size(view.size)?;
        tracer.set_camera(view.camera);
        tracer.set_lights(view.lights.clone());
        tracer.render(&View::Final)?;
        let gbuffer = tracer.read_gbuffer();
        self.contributing = (view.lights.iter())
            .map(|light| {
                (gbuffer.positions.iter().zip(&gbuffer.normals))
                    .map(|(p, n)| p.w > 0.5 && contributes(light, p.truncate(), *n))
                    .collect()
            })
            .collect();
        self.hard = read_traced(tracer);
        self.area = self.hard.clone();
        self.traced = Some(TracedView::of(view));
        self.samples = 0;
        self.seconds = 0.0;
        Ok(())
    }

    /// Scores `renderer`'s technique against the reference traced so far.
    fn judge(&self, renderer: &Renderer, view: JudgedView) -> Judgement {
        let image = renderer.read_output();
        let (width, height) = (view.size.x as usize, view.size.y as usize);
        let mut metrics = Vec::new();
        let mut error_maps = Vec::new();
        let coloured = renderer.scene().has_translucent_casters();
        for (i, area) in self.area.iter().enumerate() {
            let reference = light_reference(
                self.contributing[i].clone(),
                &self.hard[i],
                area,
                self.samples.max(1),
                coloured,
            );
            let (visibility, _) = scored_visibility(renderer, i);
            let supported = renderer.technique().supports(view.lights[i].kind);
            metrics.push(
                supported.then(|| Metrics::compute(&reference, &visibility, width, height, None)),
            );
            error_maps.push(error_map(&reference, &visibility, &image));
        }
        let counters = (self.tracer.as_ref()).map(|t| t.technique_instance().counters());
        let triangles = counters
            .and_then(|c| counter(&c, "BVH triangles"))
            .unwrap_or(0.0);
        Judgement {
            view,
            metrics,
            error_maps,
            occluder_triangles: triangles as usize,
            seconds: self.seconds,
            live_samples: Some(self.samples),
        }
    }
}
