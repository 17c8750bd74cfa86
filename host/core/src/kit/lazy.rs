//! A technique's GPU state, built at the first `prepare` (when the device, scene and lights
//! are known) and read by `record`, the debug views and the counters.

use crate::technique::{TechniqueError, TechniqueResult};

/// GPU state built on first use: [`Self::prepare`] builds it, and reading it before that is
/// [`TechniqueError::not_prepared`].
pub struct LazyGpu<G>(Option<G>);

impl<G> Default for LazyGpu<G> {
    fn default() -> Self {
        LazyGpu(None)
    }
}

impl<G> LazyGpu<G> {
    /// The state, built by `build` first when there is none yet or when `rebuild` (a failed
    /// build keeps the previous state).
    pub fn prepare(
        &mut self,
        rebuild: bool,
        build: impl FnOnce() -> TechniqueResult<G>,
    ) -> TechniqueResult<&mut G> {
        if rebuild || self.0.is_none() {
            self.0 = Some(build()?);
        }
        Ok(self.0.as_mut().expect("built above"))
    }

    /// The state, or the not-prepared error.
    pub fn get(&self) -> TechniqueResult<&G> {
        self.0.as_ref().ok_or_else(TechniqueError::not_prepared)
    }

    /// The state to update, or the not-prepared error.
    pub fn get_mut(&mut self) -> TechniqueResult<&mut G> {
        self.0.as_mut().ok_or_else(TechniqueError::not_prepared)
    }

    /// The state once built (for resources, debug views and counters, which are empty before).
    pub fn built(&self) -> Option<&G> {
        self.0.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn state_is_built_once_unless_rebuilt_and_absent_state_is_an_error() {
        let mut lazy = LazyGpu::<u32>::default();
        assert!(lazy.get().is_err() && lazy.built().is_none());
        let mut builds = 0;
        for rebuild in [false, false, true] {
            lazy.prepare(rebuild, || {
                builds += 1;
                Ok(builds)
            })
            .unwrap();
        }
        assert_eq!((builds, *lazy.get().unwrap()), (2, 2));
        let failed = lazy.prepare(true, || Err(TechniqueError::Other("no".into())));
        assert!(failed.is_err());
        assert_eq!(*lazy.get().unwrap(), 2, "a failed rebuild keeps the state");
    }
}
