//! What to run: sweeps, plans and their expansion into configurations.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use zoo_host::TechniqueRegistration;
use zoo_host::params::{self, ParamValues};
use zoo_host::scene::SceneDescription;

pub use crate::cli::PathMode;
use crate::cli::{BenchArgs, parse_size};

/// A swept quantity.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepKey {
    /// Output size (`size=256x256,512x512`).
    Size,
    /// Procedural tessellation factor (`scene.tessellation=0.5,1,2`).
    Tessellation,
    /// The scene's first N lights (`scene.lights=1,4,16`), for costs per added light.
    Lights,
    /// A technique parameter (`sm-pcf.map_size=512,1024`).
    Param { technique: String, key: String },
}

impl SweepKey {
    /// Whether configurations of `technique` are swept over it (a technique's parameter
    /// sweeps that technique's configurations only).
    pub fn applies_to(&self, technique: &str) -> bool {
        match self {
            SweepKey::Param { technique: t, .. } => t == technique,
            _ => true,
        }
    }
}

/// One sweep: a key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub key: SweepKey,
    pub name: String,
    pub values: Vec<String>,
}

/// Parses `KEY` of `--sweep KEY=v1,v2`.
pub fn parse_sweep(key: &str, values: &[String]) -> anyhow::Result<Sweep> {
    if values.is_empty() || values.iter().any(|v| v.trim().is_empty()) {
        bail!("--sweep {key}: give at least one value, e.g. {key}=a,b");
    }
    let parsed = match key {
        "size" => {
            for v in values {
                parse_size(v).map_err(|e| anyhow::anyhow!("--sweep size: {e}"))?;
            }
            SweepKey::Size
        }
        "scene.tessellation" => {
            for v in values {
                match v.parse::<f32>() {
                    Ok(f) if f > 0.0 && f <= 16.0 => {}
                    _ => bail!("--sweep scene.tessellation: `{v}` is not a factor in (0, 16]"),
                }
            }
            SweepKey::Tessellation
        }
        "scene.lights" => {
            for v in values {
                match v.parse::<usize>() {
                    Ok(n) if (1..=zoo_host::MAX_LIGHTS).contains(&n) => {}
                    _ => bail!(
                        "--sweep scene.lights: `{v}` is not a light count in 1..={}",
                        zoo_host::MAX_LIGHTS
                    ),
                }
            }
            SweepKey::Lights
        }
        other => match other.split_once('.') {
            Some((technique, param)) => {
                let registration = zoo_host::find_technique(technique)?;
                let schema = (registration.params)();
                let spec = params::find_spec(&schema, param)
                    .with_context(|| format!("--sweep {other}"))?;
                for v in values {
                    spec.parse(v).with_context(|| format!("--sweep {other}"))?;
                }
                SweepKey::Param {
                    technique: technique.to_string(),
                    key: param.to_string(),
                }
            }
            None => bail!(
                "--sweep {other}: expected size, scene.tessellation, scene.lights or TECHNIQUE.PARAM"
            ),
        },
    };
    Ok(Sweep {
        key: parsed,
        name: key.to_string(),
        values: values.iter().map(|v| v.trim().to_string()).collect(),
    })
}

/// Everything one benchmark run needs.
pub struct BenchPlan {
    pub run: String,
    pub scene_path: PathBuf,
    pub description: SceneDescription,
    pub techniques: Vec<&'static TechniqueRegistration>,
    pub size: zoo_host::glam::UVec2,
    pub frames: u32,
    pub warmup: u32,
    pub path: PathMode,
    pub sweeps: Vec<Sweep>,
    /// Fixed parameters as (technique, key, value).
    pub set: Vec<(String, String, String)>,
    pub flicker: bool,
    /// Time passes on the CPU clock ([`zoo_host::Renderer::set_cpu_timing`]).
    pub cpu_timing: bool,
    /// Let frames keep unchanged work ([`zoo_host::Renderer::set_reuse_unchanged`]).
    pub reuse_unchanged: bool,
}

/// One measured configuration.
#[derive(Debug, Clone)]
pub struct Configuration {
    pub run: String,
    pub technique: &'static TechniqueRegistration,
    pub params: ParamValues,
    /// The swept values that define it, as `key=value`.
    pub swept: Vec<(String, String)>,
    pub size: zoo_host::glam::UVec2,
    pub tessellation: f32,
    /// Only the scene's first lights, when swept.
    pub lights: Option<usize>,
}

impl Configuration {
    /// `technique [key=value, ...]`.
    pub fn label(&self) -> String {
        if self.swept.is_empty() {
            self.technique.id.to_string()
        } else {
            let swept: Vec<String> = self.swept.iter().map(|(k, v)| format!("{k}={v}")).collect();
            format!("{} [{}]", self.technique.id, swept.join(", "))
        }
    }

    /// Swept values that apply to every technique (size, tessellation, light count).
    pub(super) fn common_key(&self) -> String {
        let lights = self
            .lights
            .map_or(String::new(), |n| format!(" {n} lights"));
        format!(
            "{}x{}@{}{lights}",
            self.size.x, self.size.y, self.tessellation
        )
    }
}

/// Expands the plan's sweeps into configurations (cartesian product; a technique-parameter
/// sweep only multiplies its own technique's configurations).
pub fn expand(plan: &BenchPlan) -> anyhow::Result<Vec<Configuration>> {
    let mut out = Vec::new();
    for technique in &plan.techniques {
        let schema = (technique.params)();
        let mut base = params::defaults(&schema);
        let fixed: Vec<(String, String)> = plan
            .set
            .iter()
            .filter(|(t, _, _)| t == technique.id)
            .map(|(_, k, v)| (k.clone(), v.clone()))
            .collect();
        params::apply_assignments(&schema, &mut base, &fixed)
            .with_context(|| format!("technique `{}`", technique.id))?;
        let configs = vec![Configuration {
            run: plan.run.clone(),
            technique,
            params: base,
            swept: Vec::new(),
            size: plan.size,
            tessellation: 1.0,
            lights: None,
        }];
        let own: Vec<&Sweep> = plan
            .sweeps
            .iter()
            .filter(|sweep| sweep.key.applies_to(technique.id))
            .collect();
        let configs = cartesian(configs, &own, |c, sweep, value| {
            match &sweep.key {
                SweepKey::Size => c.size = parse_size(value).map_err(|e| anyhow::anyhow!(e))?,
                SweepKey::Tessellation => c.tessellation = value.parse()?,
                SweepKey::Lights => c.lights = Some(value.parse()?),
                SweepKey::Param { key, .. } => {
                    params::apply_assignments(
                        &schema,
                        &mut c.params,
                        &[(key.clone(), value.to_string())],
                    )?;
                }
            }
            c.swept.push((sweep.name.clone(), value.to_string()));
            Ok(())
        })?;
        out.extend(configs);
    }
    Ok(out)
}

/// The cartesian product of `configs` with the values of each of `sweeps`, in order: `apply`
/// sets one sweep's value on a copy of a configuration.
pub fn cartesian<C: Clone>(
    mut configs: Vec<C>,
    sweeps: &[&Sweep],
    mut apply: impl FnMut(&mut C, &Sweep, &str) -> anyhow::Result<()>,
) -> anyhow::Result<Vec<C>> {
    for sweep in sweeps {
        let mut next = Vec::with_capacity(configs.len() * sweep.values.len());
        for config in &configs {
            for value in &sweep.values {
                let mut c = config.clone();
                apply(&mut c, sweep, value)?;
                next.push(c);
            }
        }
        configs = next;
    }
    Ok(configs)
}

/// Parses the `--sweep KEY=v1,v2,...` arguments.
pub fn parse_sweeps(args: &[(String, String)]) -> anyhow::Result<Vec<Sweep>> {
    args.iter()
        .map(|(key, values)| {
            let values: Vec<String> = values.split(',').map(str::to_string).collect();
            parse_sweep(key, &values)
        })
        .collect()
}

/// Builds the plan for a command-line run.
pub fn plan_from_args(args: &BenchArgs, scene: &Path) -> anyhow::Result<BenchPlan> {
    let mut techniques = crate::compare::select_techniques(&args.techniques)?;
    // The baseline every ratio is taken against.
    let baseline = zoo_host::find_technique(zoo_host::builtin::UNSHADOWED_ID)?;
    if !techniques.iter().any(|t| t.id == baseline.id) {
        techniques.insert(0, baseline);
    }
    let sweeps = parse_sweeps(&args.sweep)?;
    let set = split_sets(&args.set, &techniques)?;
    Ok(BenchPlan {
        run: scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "bench".into()),
        scene_path: scene.to_path_buf(),
        description: zoo_host::scene::read_description(scene)?,
        techniques,
        size: args.size,
        frames: args.frames.unwrap_or(30),
        warmup: args.warmup,
        path: args.path,
        sweeps,
        set,
        flicker: !args.no_flicker,
        cpu_timing: args.cpu_timing,
        reuse_unchanged: args.reuse_unchanged,
    })
}

pub(super) fn split_sets(
    set: &[(String, String)],
    techniques: &[&'static TechniqueRegistration],
) -> anyhow::Result<Vec<(String, String, String)>> {
    set.iter()
        .map(|(key, value)| {
            let (id, k) = key
                .split_once('.')
                .with_context(|| format!("--set {key}: expected ID.KEY=VALUE"))?;
            if !techniques.iter().any(|t| t.id == id) {
                bail!("--set {key}: technique `{id}` is not being benchmarked");
            }
            Ok((id.to_string(), k.to_string(), value.clone()))
        })
        .collect()
}
