//! A technique instance and the guard that turns its errors, panics and GPU validation
//! errors into a [`TechniqueError`], so a failing plugin is disabled, never the app.

use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::gpu::GpuContext;
use crate::params::{self, ParamValues};
use crate::technique::{Changes, ShadowTechnique, TechniqueError, TechniqueRegistration};

pub(super) struct ActiveTechnique {
    pub(super) registration: &'static TechniqueRegistration,
    pub(super) params: ParamValues,
    pub(super) instance: Box<dyn ShadowTechnique>,
    pub(super) pending: Changes,
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// Runs plugin code, turning panics and wgpu validation errors into [`TechniqueError`]s.
pub(super) fn guarded<T>(
    gpu: &GpuContext,
    id: &str,
    f: impl FnOnce() -> Result<T, TechniqueError>,
) -> Result<T, TechniqueError> {
    let (outcome, validation) = gpu.validation_scope(|| catch_unwind(AssertUnwindSafe(f)));
    let value = match outcome {
        Ok(result) => result?,
        Err(payload) => {
            return Err(TechniqueError::Panicked {
                id: id.to_string(),
                message: panic_message(payload.as_ref()),
            });
        }
    };
    match validation {
        Some(message) => Err(TechniqueError::Validation {
            id: id.to_string(),
            message,
        }),
        None => Ok(value),
    }
}

/// Creates a technique through its factory after validating `values` against its schema.
pub(super) fn instantiate(
    gpu: &GpuContext,
    registration: &'static TechniqueRegistration,
    values: &ParamValues,
) -> Result<ActiveTechnique, TechniqueError> {
    if let Some(reason) = registration.unavailable_reason(gpu) {
        return Err(TechniqueError::Unavailable {
            id: registration.id.to_string(),
            reason,
        });
    }
    let schema = (registration.params)();
    let mut params = params::defaults(&schema);
    for (key, value) in values {
        params::find_spec(&schema, key)?.check(value)?;
        params.insert(key.clone(), value.clone());
    }
    let instance = guarded(gpu, registration.id, || (registration.create)(gpu, &params))?;
    Ok(ActiveTechnique {
        registration,
        params,
        instance,
        pending: Changes::ALL,
    })
}
