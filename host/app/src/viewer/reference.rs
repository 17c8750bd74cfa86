//! The reference overlay: judges the current view against ray-traced visibility, on demand by
//! the CPU judge on a background thread ("Judge view"), or live on the GPU as the view changes
//! ([`LiveReference`]), and shows the error map with its metrics.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread::JoinHandle;
use web_time::Instant;

use zoo_host::judge::{Metrics, Occluders, Surfaces, reference_visibility};
use zoo_host::judging::{DEFAULT_SAMPLES, error_map, surface_points};
use zoo_host::{Renderer, View};

use super::judgement::{JudgedView, Judgement};
use super::live::{LiveReference, RAYS_PER_FRAME};

/// A judgement being computed.
struct Running {
    view: JudgedView,
    lights_done: Arc<AtomicUsize>,
    light_count: usize,
    worker: JoinHandle<Judgement>,
}

/// Why the CPU judge cannot run here, where it cannot: it traces on a thread of its own and
/// reads the frame back as it ends.
const CPU_JUDGE_UNAVAILABLE: Option<&str> = if cfg!(target_arch = "wasm32") {
    Some(
        "The CPU judge needs a thread beside the page's and a frame read back at once; this \
         browser build has neither (no shared-memory workers). Use the live GPU judge, or the \
         native `shadow-zoo compare`.",
    )
} else {
    None
};

/// The overlay's state: idle, judging in the background, or showing a result.
#[derive(Default)]
pub struct ReferenceOverlay {
    running: Option<Running>,
    pub result: Option<Judgement>,
    /// Which light's error map is shown.
    pub light: usize,
    pub opacity: f32,
    pub visible: bool,
    /// Whether the view is judged live on the GPU, following every change.
    pub live: bool,
    live_reference: LiveReference,
    texture: Option<(usize, egui::TextureHandle)>,
}

impl ReferenceOverlay {
    /// An idle overlay.
    pub fn new() -> ReferenceOverlay {
        ReferenceOverlay {
            opacity: 0.85,
            visible: true,
            ..Default::default()
        }
    }

    /// Starts judging what `renderer` shows (the final image is rendered first). The G-buffer,
    /// the technique's visibility and the image are read now; tracing runs on a thread.
    pub fn start(&mut self, renderer: &mut Renderer) -> anyhow::Result<()> {
        renderer.render(&View::Final)?;
        let view = JudgedView::of(renderer);
        let gbuffer = renderer.read_gbuffer();
        let image = renderer.read_output();
        let visibility: Vec<Vec<f32>> = (0..renderer.lights().len())
            .map(|i| renderer.read_visibility(i))
            .collect();
        let supported: Vec<bool> = renderer
            .lights()
            .iter()
            .map(|l| renderer.technique().supports(l.kind))
            .collect();
        let scene = renderer.scene().clone();
        let lights = renderer.lights().to_vec();
        let light_count = lights.len();
        let lights_done = Arc::new(AtomicUsize::new(0));
        let done = lights_done.clone();
        let key = view.clone();
        let worker = std::thread::Builder::new()
            .name("reference judge".into())
            .spawn(move || {
                let start = Instant::now();
                let occluders = Occluders::new(&scene);
                let points = surface_points(&gbuffer, &Surfaces::new(&scene));
                let (width, height) = (gbuffer.size.x as usize, gbuffer.size.y as usize);
                let mut metrics = Vec::new();
                let mut error_maps = Vec::new();
                for (i, light) in lights.iter().enumerate() {
                    let reference =
                        reference_visibility(&occluders, light, &points, DEFAULT_SAMPLES);
                    metrics.push(supported[i].then(|| {
                        Metrics::compute(&reference, &visibility[i], width, height, None)
                    }));
                    error_maps.push(error_map(&reference, &visibility[i], &image));
                    done.fetch_add(1, Ordering::Relaxed);
                }
                Judgement {
                    view: key,
                    metrics,
                    error_maps,
                    occluder_triangles: occluders.len(),
                    seconds: start.elapsed().as_secs_f64(),
                    live_samples: None,
                }
            })?;
        self.running = Some(Running {
            view,
            lights_done,
            light_count,
            worker,
        });
        Ok(())
    }

    /// Judges what `renderer` shows on the GPU when the live judge is on and the view changed
    /// or has samples to add (call once per frame, after rendering); turns the live judge off
    /// on an error.
    pub fn follow(&mut self, renderer: &Renderer) -> anyhow::Result<()> {
        if !self.live {
            return Ok(());
        }
        match self.live_reference.update(renderer) {
            Ok(Some(judgement)) => {
                self.show(judgement);
                Ok(())
            }
            Ok(None) => Ok(()),
            Err(e) => {
                self.live = false;
                Err(e)
            }
        }
    }

    /// Whether the live judge waits for the GPU to read its traces and the judged frame back
    /// (natively it does, and each frame's verdict is its own), or collects them frames later,
    /// as it must in a browser. Restarts the live judge.
    pub fn set_live_waits(&mut self, wait: bool) {
        self.live_reference = LiveReference::new(wait);
    }

    /// Area rays a pixel the live judge has traced for the current view, while it is on.
    pub fn live_samples(&self) -> Option<u32> {
        self.live.then(|| self.live_reference.samples())
    }

    fn show(&mut self, judgement: Judgement) {
        self.light = self.light.min(judgement.error_maps.len().saturating_sub(1));
        self.texture = None;
        self.result = Some(judgement);
    }

    /// Whether a judgement is being computed.
    pub fn is_running(&self) -> bool {
        self.running.is_some()
    }

    /// Lights traced so far and in all, while running.
    pub fn progress(&self) -> Option<(usize, usize)> {
        self.running
            .as_ref()
            .map(|r| (r.lights_done.load(Ordering::Relaxed), r.light_count))
    }

    /// Collects a finished judgement (call once per frame). Returns an error if the worker
    /// panicked.
    pub fn poll(&mut self) -> anyhow::Result<()> {
        if !self
            .running
            .as_ref()
            .is_some_and(|r| r.worker.is_finished())
        {
            return Ok(());
        }
        let running = self.running.take().expect("checked above");
        let judgement = running.worker.join().map_err(|_| {
            anyhow::anyhow!("the reference judge failed for {}", running.view.technique)
        })?;
        self.show(judgement);
        self.visible = true;
        Ok(())
    }

    /// Waits for a running judgement (tests and scripted use).
    pub fn wait(&mut self) -> anyhow::Result<()> {
        while self.is_running() {
            std::thread::sleep(std::time::Duration::from_millis(10));
            self.poll()?;
        }
        Ok(())
    }

    /// Whether the result no longer matches what `renderer` shows.
    pub fn is_stale(&self, renderer: &Renderer) -> bool {
        self.result
            .as_ref()
            .is_some_and(|r| r.view != JudgedView::of(renderer))
    }

    /// The error map texture to draw over the view, if one should be shown.
    pub fn overlay_texture(&mut self, ctx: &egui::Context) -> Option<egui::TextureId> {
        let result = self.result.as_ref().filter(|_| self.visible)?;
        let map = result.error_maps.get(self.light)?;
        if self
            .texture
            .as_ref()
            .is_none_or(|(light, _)| *light != self.light)
        {
            let image = egui::ColorImage::from_rgba_unmultiplied(
                [map.width() as usize, map.height() as usize],
                map.as_raw(),
            );
            let handle =
                ctx.load_texture("reference error map", image, egui::TextureOptions::NEAREST);
            self.texture = Some((self.light, handle));
        }
        self.texture.as_ref().map(|(_, t)| t.id())
    }

    /// The panel: judge button, progress, metrics and overlay controls.
    pub fn panel(&mut self, ui: &mut egui::Ui, renderer: &mut Renderer) -> Option<String> {
        let error = self.judge_controls(ui, renderer);
        let stale = self.is_stale(renderer);
        let Some(result) = &self.result else {
            return error;
        };
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.visible, "show error map");
            ui.add(egui::Slider::new(&mut self.opacity, 0.0..=1.0).text("opacity"));
        });
        if stale {
            ui.colored_label(
                egui::Color32::from_rgb(230, 160, 40),
                "stale: the view changed since it was judged (map hidden)",
            );
        }
        ui.label(judgement_summary(result));
        metrics_grid(ui, &result.metrics, &mut self.light);
        error
    }

    /// The judge button, the live toggle and the CPU judge's progress; returns why judging
    /// could not start, if it could not.
    fn judge_controls(&mut self, ui: &mut egui::Ui, renderer: &mut Renderer) -> Option<String> {
        let mut error = None;
        ui.horizontal(|ui| {
            let button = ui
                .add_enabled(
                    CPU_JUDGE_UNAVAILABLE.is_none() && !self.is_running(),
                    egui::Button::new("Judge view"),
                )
                .on_hover_text(
                    "Trace exact visibility for this view in the background and overlay \
                     where the technique disagrees",
                );
            if let Some(why) = CPU_JUDGE_UNAVAILABLE {
                ui.label("CPU judge: not in the browser").on_hover_text(why);
            }
            if button.clicked() {
                // The CPU judge, the arbiter, replaces the live one.
                self.live = false;
                if let Err(e) = self.start(renderer) {
                    error = Some(format!("cannot judge the view: {e}"));
                }
            }
            ui.checkbox(&mut self.live, "live (GPU)")
                .on_hover_text(format!(
                    "Judge the view on the GPU as it changes: hard visibility first, then \
                 {RAYS_PER_FRAME} more area rays a pixel each trace (in a browser each verdict \
                 comes a few frames after its view)"
                ));
            if let Some((done, all)) = self.progress() {
                ui.add(
                    egui::ProgressBar::new(done as f32 / all.max(1) as f32)
                        .text(format!("tracing light {}/{all}", (done + 1).min(all)))
                        .animate(true),
                );
            }
        });
        error
    }
}

/// One line on a judgement: the technique, what traced the reference and how long it took,
/// and the error map's colours.
fn judgement_summary(result: &Judgement) -> String {
    let traced = match result.live_samples {
        Some(0) => "live on the GPU, hard visibility".to_string(),
        Some(samples) => format!("live on the GPU, {samples} area rays a pixel"),
        None => "by the CPU judge".to_string(),
    };
    format!(
        "{} · {} triangles traced {traced} in {:.2} s · red false shadow, blue false lit",
        result.view.technique, result.occluder_triangles, result.seconds
    )
}

/// Each light's metrics, one row per light; clicking a light's number selects its error
/// map.
fn metrics_grid(ui: &mut egui::Ui, metrics: &[Option<Metrics>], selected: &mut usize) {
    egui::Grid::new("reference metrics")
        .striped(true)
        .show(ui, |ui| {
            for heading in ["light", "false shadow", "false lit", "core fs/fl", "mae"] {
                ui.strong(heading);
            }
            ui.end_row();
            for (i, metrics) in metrics.iter().enumerate() {
                if ui
                    .selectable_label(*selected == i, format!("{i}"))
                    .clicked()
                {
                    *selected = i;
                }
                match metrics {
                    Some(m) => {
                        ui.label(format!("{:.4}", m.false_shadow));
                        ui.label(format!("{:.4}", m.false_lit));
                        ui.label(format!(
                            "{:.4}/{:.4}",
                            m.false_shadow_core, m.false_lit_core
                        ));
                        ui.label(format!("{:.4}", m.mae));
                    }
                    None => {
                        ui.label("not supported");
                    }
                }
                ui.end_row();
            }
        });
}
