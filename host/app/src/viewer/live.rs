//! The live reference: while it is on, the view is judged against visibility traced on the
//! GPU by the GPU judge's tracer (`rt-shadows`, in a renderer of its own) whenever it changes:
//! hard visibility first, then [`RAYS_PER_FRAME`] area rays a pixel and light added each trace
//! up to the GPU judge's [`MAX_SAMPLES`], the technique scored against it each time; a change
//! of technique or parameters is judged against what is traced. Which pixels a light reaches
//! comes from the G-buffer's surfaces ("Judge view" runs the CPU judge, the arbiter, which
//! locates them on the exact triangles). Behind translucent casters a soft light's colour is
//! the last trace's rays' (rt-shadows averages visibility over frames, not colour).
//!
//! Traces and the judged frames are read back without blocking a frame where nothing may wait
//! for the GPU (the browser): there a verdict arrives a few frames after its view. Natively the
//! viewer waits, and each frame's verdict is its own.

use web_time::Instant;

use zoo_host::glam::Vec3;
use zoo_host::judge::Metrics;
use zoo_host::judging::{error_map, scored};
use zoo_host::render::{PendingReadout, Readout, ReadoutRequest};
use zoo_host::scene::shading::contributes;
use zoo_host::technique::counter;
use zoo_host::{Renderer, View};

use super::judgement::{JudgedView, Judgement};
use crate::gpu_judge::{MAX_SAMPLES, TRACER, light_reference, traced_colour, tracer_values};

/// Area rays a pixel and light each trace adds.
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

/// A trace on its way back: of `view`, with `samples` area rays a pixel (0: hard visibility,
/// read with the G-buffer).
struct Trace {
    view: TracedView,
    samples: u32,
    readout: PendingReadout,
    started: Instant,
}

/// A frame of the judged technique on its way back.
struct JudgedFrame {
    view: JudgedView,
    readout: PendingReadout,
}

/// The tracer and what it has traced of the current view.
pub struct LiveReference {
    tracer: Option<Renderer>,
    /// Whether readbacks wait for the GPU (natively) or arrive frames later (the browser).
    wait: bool,
    /// What the tracer traced (`None` until a trace of it arrives).
    traced: Option<TracedView>,
    tracing: Option<Trace>,
    judging: Option<JudgedFrame>,
    /// What the last verdict judged, and against how many area rays a pixel.
    judged: Option<(JudgedView, u32)>,
    /// Per light: the pixels it reaches, and the colour fraction of it that arrives there from
    /// its centre.
    contributing: Vec<Vec<bool>>,
    hard: Vec<Vec<Vec3>>,
    /// Per light: the colour fraction of its area that arrives (the hard one until area rays
    /// are traced).
    area: Vec<Vec<Vec3>>,
    /// Area rays a pixel traced for the current view (0: hard visibility only).
    samples: u32,
    /// Tracing time spent on the current view, from each trace's start to its arrival.
    seconds: f64,
}

impl Default for LiveReference {
    fn default() -> LiveReference {
        LiveReference::new(!cfg!(target_arch = "wasm32"))
    }
}

impl LiveReference {
    /// An idle live reference whose readbacks wait for the GPU when `wait`.
    pub fn new(wait: bool) -> LiveReference {
        LiveReference {
            tracer: None,
            wait,
            traced: None,
            tracing: None,
            judging: None,
            judged: None,
            contributing: Vec::new(),
            hard: Vec::new(),
            area: Vec::new(),
            samples: 0,
            seconds: 0.0,
        }
    }

    /// Area rays a pixel traced so far for the current view.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Traces more of the reference of what `renderer` shows (rendered this frame) and judges
    /// its technique against it: the new judgement, or `None` while nothing new has arrived
    /// or once the view has all its samples and nothing judged changed. A change of technique
    /// or parameters is judged against the samples already traced.
    pub fn update(&mut self, renderer: &Renderer) -> anyhow::Result<Option<Judgement>> {
        let view = JudgedView::of(renderer);
        if self.tracing.is_none() {
            self.start_trace(renderer, &view)?;
        }
        if let Some(trace) = &mut self.tracing
            && let Some(readout) = trace.readout.poll(renderer.gpu(), self.wait)
        {
            let trace = self.tracing.take().expect("polled above");
            self.arrive(trace, readout.map_err(anyhow::Error::msg)?);
        }
        let traced = self.traced.as_ref() == Some(&TracedView::of(&view));
        let key = (view, self.samples);
        if self.judging.is_none() && traced && self.judged.as_ref() != Some(&key) {
            let request = ReadoutRequest {
                output: true,
                lights: true,
                ..Default::default()
            };
            self.judging = Some(JudgedFrame {
                view: key.0,
                readout: renderer.request_readout(request),
            });
        }
        let Some(judging) = &mut self.judging else {
            return Ok(None);
        };
        let Some(readout) = judging.readout.poll(renderer.gpu(), self.wait) else {
            return Ok(None);
        };
        let judging = self.judging.take().expect("polled above");
        let readout = readout.map_err(anyhow::Error::msg)?;
        // A trace of another view may have arrived meanwhile: judge against it only its own.
        if self.traced.as_ref() != Some(&TracedView::of(&judging.view)) {
            return Ok(None);
        }
        self.judged = Some((judging.view.clone(), self.samples));
        Ok(Some(self.judge(renderer, judging.view, readout)))
    }

    /// Starts the next trace: hard visibility and the G-buffer when the view is not the one
    /// traced, else more area rays until it has [`MAX_SAMPLES`].
    fn start_trace(&mut self, renderer: &Renderer, view: &JudgedView) -> anyhow::Result<()> {
        let traced_view = TracedView::of(view);
        if self.traced.as_ref() == Some(&traced_view) {
            if self.samples >= MAX_SAMPLES {
                return Ok(());
            }
            let tracer = self.tracer.as_mut().expect("a view was traced");
            if self.samples == 0 {
                // Parameters only: the tracer keeps its pipelines and hierarchy.
                let frames = MAX_SAMPLES / RAYS_PER_FRAME;
                tracer.set_params(&tracer_values(RAYS_PER_FRAME, frames)?)?;
            }
            let started = Instant::now();
            tracer.render(&View::Final)?;
            let request = ReadoutRequest {
                lights: true,
                ..Default::default()
            };
            self.tracing = Some(Trace {
                view: traced_view,
                samples: self.samples + RAYS_PER_FRAME,
                readout: tracer.request_readout(request),
                started,
            });
            return Ok(());
        }
        // Until this trace arrives the tracer holds no view that was traced.
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
        let started = Instant::now();
        tracer.set_size(view.size)?;
        tracer.set_camera(view.camera);
        tracer.set_lights(view.lights.clone());
        tracer.render(&View::Final)?;
        let request = ReadoutRequest {
            gbuffer: true,
            lights: true,
            ..Default::default()
        };
        self.tracing = Some(Trace {
            view: traced_view,
            samples: 0,
            readout: tracer.request_readout(request),
            started,
        });
        Ok(())
    }

    /// Takes in a trace that arrived: a new view's hard visibility and the pixels each light
    /// reaches, or more area rays of the view traced.
    fn arrive(&mut self, trace: Trace, readout: Readout) {
        let traced: Vec<Vec<Vec3>> = (readout.visibility.iter().zip(&readout.transmittance))
            .map(|(v, t)| traced_colour(v, t.as_deref()))
            .collect();
        let seconds = trace.started.elapsed().as_secs_f64();
        match readout.gbuffer {
            Some(gbuffer) => {
                self.contributing = (trace.view.lights.iter())
                    .map(|light| {
                        (gbuffer.positions.iter().zip(&gbuffer.normals))
                            .map(|(p, n)| p.w > 0.5 && contributes(light, p.truncate(), *n))
                            .collect()
                    })
                    .collect();
                self.hard = traced;
                self.area = self.hard.clone();
                self.samples = 0;
                self.seconds = seconds;
                self.traced = Some(trace.view);
            }
            None if self.traced.as_ref() == Some(&trace.view) => {
                self.area = traced;
                self.samples = trace.samples;
                self.seconds += seconds;
            }
            // Area rays of a view no longer traced.
            None => {}
        }
    }

    /// Scores the technique's `frame` of `view` against the reference traced so far.
    fn judge(&self, renderer: &Renderer, view: JudgedView, frame: Readout) -> Judgement {
        let image = frame.output.expect("the judged frame's image is read");
        let (width, height) = (view.size.x as usize, view.size.y as usize);
        let mut metrics = Vec::new();
        let mut error_maps = Vec::new();
        let coloured = renderer.scene().has_translucent_casters();
        let technique = zoo_host::find_technique(&view.technique).ok();
        let frame_lights = frame.visibility.into_iter().zip(frame.transmittance);
        for (i, (area, (visibility, transmittance))) in
            self.area.iter().zip(frame_lights).enumerate()
        {
            let reference = light_reference(
                self.contributing[i].clone(),
                &self.hard[i],
                area,
                self.samples.max(1),
                coloured,
            );
            let visibility = scored(visibility, transmittance.as_deref());
            let supported = technique.is_some_and(|t| t.supports(view.lights[i].kind));
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
