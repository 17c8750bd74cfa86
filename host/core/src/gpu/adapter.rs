//! Choosing an adapter that can run the host: what it must offer, and why others are rejected.
//!
//! An adapter is only used once it has been checked against what the host's passes need
//! (downlevel capabilities, render and sampled formats, limits). Among the adapters that qualify,
//! Vulkan, Metal and DX12 come before other backends, then discrete before integrated, virtual
//! and CPU devices. When none qualifies, the error lists every adapter found with its reasons.

use crate::render::gbuffer::{
    ALBEDO_FORMAT, DEPTH_FORMAT, GBUFFER_USAGE, NORMAL_FORMAT, VIEW_DEPTH_FORMAT,
};
use crate::render::lighting::{OUTPUT_FORMAT, OUTPUT_USAGE};
use crate::render::visibility::{
    INDIRECT_FORMAT, INDIRECT_USAGE, VISIBILITY_FORMAT, VISIBILITY_USAGE,
};

/// Downlevel capabilities the host's own passes rely on (storage buffers of per-frame data
/// read in vertex shaders). Techniques declare what they need beyond this.
pub const HOST_DOWNLEVEL_FLAGS: wgpu::DownlevelFlags = wgpu::DownlevelFlags::VERTEX_STORAGE;

/// Usages the host creates each of its texture formats with (the constants its textures are
/// created from, so the check cannot drift from the code).
pub fn host_formats() -> [(wgpu::TextureFormat, wgpu::TextureUsages); 7] {
    [
        (VIEW_DEPTH_FORMAT, GBUFFER_USAGE),
        (NORMAL_FORMAT, GBUFFER_USAGE),
        (ALBEDO_FORMAT, GBUFFER_USAGE),
        (DEPTH_FORMAT, GBUFFER_USAGE),
        (VISIBILITY_FORMAT, VISIBILITY_USAGE),
        (INDIRECT_FORMAT, INDIRECT_USAGE),
        (OUTPUT_FORMAT, OUTPUT_USAGE),
    ]
}

/// Limits the host needs.
pub fn host_limits() -> wgpu::Limits {
    wgpu::Limits::downlevel_defaults()
}

/// Why an adapter cannot run the host (empty when it can).
pub fn rejection_reasons(adapter: &wgpu::Adapter) -> Vec<String> {
    let mut reasons = Vec::new();
    let downlevel = adapter.get_downlevel_capabilities();
    let missing = HOST_DOWNLEVEL_FLAGS - downlevel.flags;
    if !missing.is_empty() {
        let names: Vec<String> = missing.iter_names().map(|(n, _)| n.to_string()).collect();
        reasons.push(format!("lacks downlevel {}", names.join(", ")));
    }
    for (format, usages) in host_formats() {
        let allowed = adapter.get_texture_format_features(format).allowed_usages;
        let lacking = usages - allowed;
        if !lacking.is_empty() {
            reasons.push(format!("{format:?} cannot be used as {lacking:?}"));
        }
    }
    host_limits().check_limits_with_fail_fn(&adapter.limits(), false, |name, wanted, allowed| {
        reasons.push(format!("limit {name} {allowed} < {wanted}"))
    });
    reasons
}

/// Sort key: Vulkan/Metal/DX12 first, then discrete, integrated, virtual, CPU.
fn rank(backend: wgpu::Backend, device_type: wgpu::DeviceType) -> (u8, u8) {
    let backend = match backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    let device = match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    (backend, device)
}

/// One adapter and why it was not used.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejected {
    /// Name and backend, e.g. `llvmpipe (Gl backend)`.
    pub adapter: String,
    /// Reasons, one per unmet need.
    pub reasons: Vec<String>,
}

/// Why no adapter was chosen.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AdapterError {
    /// No adapter on any enabled backend.
    #[error("no graphics adapter found (backends: {backends}). {}", install_hint())]
    NoAdapter { backends: String },
    /// `WGPU_ADAPTER_NAME` matched nothing.
    #[error("WGPU_ADAPTER_NAME={wanted} matches no adapter; available: {available}")]
    NoMatchingAdapter { wanted: String, available: String },
    /// Adapters exist, but none can run the host.
    #[error("{}", describe_rejections(.0))]
    NoneQualifies(Vec<Rejected>),
}

fn adapter_label(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?} backend, {:?})",
        info.name, info.backend, info.device_type
    )
}

fn describe_rejections(rejected: &[Rejected]) -> String {
    let mut text = String::from("no usable graphics adapter; found:");
    for r in rejected {
        text.push_str(&format!(
            "\n  - {}: rejected: {}",
            r.adapter,
            r.reasons.join("; ")
        ));
    }
    text.push('\n');
    text.push_str(&install_hint());
    text
}

/// How to get a driver that runs Shadow Zoo on this platform.
pub fn install_hint() -> String {
    let fix = if cfg!(target_os = "linux") {
        "On Linux without a suitable GPU driver install Mesa's software drivers: \
         `sudo apt-get install -y mesa-vulkan-drivers libegl-mesa0` (Fedora: \
         `sudo dnf install mesa-vulkan-drivers mesa-libEGL`)"
    } else if cfg!(target_os = "windows") {
        "On Windows update the GPU driver (DX12 or Vulkan); without a GPU, WARP comes with Windows 10 and later"
    } else if cfg!(target_os = "macos") {
        "On macOS Metal is built in; update macOS if no adapter is found"
    } else {
        "Install a Vulkan driver"
    };
    format!("Shadow Zoo needs a Vulkan, Metal, DX12 or OpenGL adapter. {fix}.")
}

/// Chooses the best adapter among `adapters` that can run the host, honouring
/// `WGPU_ADAPTER_NAME` (a case-insensitive substring of the adapter's name).
pub fn choose_adapter(
    adapters: &[wgpu::Adapter],
    backends: wgpu::Backends,
) -> Result<wgpu::Adapter, AdapterError> {
    choose_adapter_with(adapters, backends, |_| None)
}

/// [`choose_adapter`] with one more need: `also` returns why an adapter is unfit (for
/// example, that it cannot present to the viewer's window).
pub fn choose_adapter_with(
    adapters: &[wgpu::Adapter],
    backends: wgpu::Backends,
    also: impl Fn(&wgpu::Adapter) -> Option<String>,
) -> Result<wgpu::Adapter, AdapterError> {
    if adapters.is_empty() {
        return Err(AdapterError::NoAdapter {
            backends: format!("{backends:?}"),
        });
    }
    let wanted = std::env::var("WGPU_ADAPTER_NAME").ok();
    let candidates: Vec<&wgpu::Adapter> = match &wanted {
        Some(wanted) => {
            let needle = wanted.to_lowercase();
            let matching: Vec<&wgpu::Adapter> = adapters
                .iter()
                .filter(|a| a.get_info().name.to_lowercase().contains(&needle))
                .collect();
            if matching.is_empty() {
                let names: Vec<String> = adapters
                    .iter()
                    .map(|a| adapter_label(&a.get_info()))
                    .collect();
                return Err(AdapterError::NoMatchingAdapter {
                    wanted: wanted.clone(),
                    available: names.join(", "),
                });
            }
            matching
        }
        None => adapters.iter().collect(),
    };
    let mut rejected = Vec::new();
    let mut usable = Vec::new();
    for adapter in candidates {
        let mut reasons = rejection_reasons(adapter);
        reasons.extend(also(adapter));
        if reasons.is_empty() {
            usable.push(adapter);
        } else {
            rejected.push(Rejected {
                adapter: adapter_label(&adapter.get_info()),
                reasons,
            });
        }
    }
    usable
        .into_iter()
        .min_by_key(|a| {
            let info = a.get_info();
            rank(info.backend, info.device_type)
        })
        .cloned()
        .ok_or(AdapterError::NoneQualifies(rejected))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejections_list_every_adapter_and_the_fix() {
        let text = AdapterError::NoneQualifies(vec![
            Rejected {
                adapter: "llvmpipe (Gl backend, Cpu)".into(),
                reasons: vec![
                    "lacks downlevel VIEW_FORMATS".into(),
                    "Rgba32Float cannot be used as RENDER_ATTACHMENT".into(),
                ],
            },
            Rejected {
                adapter: "other (Gl backend, Other)".into(),
                reasons: vec!["limit max_bind_groups 2 < 4".into()],
            },
        ])
        .to_string();
        assert!(
            text.starts_with("no usable graphics adapter; found:"),
            "{text}"
        );
        assert!(
            text.contains(
                "llvmpipe (Gl backend, Cpu): rejected: lacks downlevel VIEW_FORMATS; Rgba32Float"
            ),
            "{text}"
        );
        assert!(
            text.contains("other (Gl backend, Other): rejected: limit max_bind_groups 2 < 4"),
            "{text}"
        );
        #[cfg(target_os = "linux")]
        assert!(
            text.contains("sudo apt-get install -y mesa-vulkan-drivers"),
            "{text}"
        );
    }

    #[test]
    fn native_backends_rank_before_others_then_by_device_type() {
        use wgpu::{Backend, DeviceType};
        assert!(
            rank(Backend::Vulkan, DeviceType::Cpu) < rank(Backend::Gl, DeviceType::DiscreteGpu)
        );
        assert!(
            rank(Backend::Vulkan, DeviceType::DiscreteGpu)
                < rank(Backend::Vulkan, DeviceType::IntegratedGpu)
        );
        assert!(
            rank(Backend::Metal, DeviceType::IntegratedGpu)
                < rank(Backend::Vulkan, DeviceType::Cpu)
        );
    }
}
