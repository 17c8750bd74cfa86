//! The reference judge's integration tests in one test binary: closed-form shadows
//! (`analytic`), the one-bounce reference (`indirect`), the leak measure's unlit surfaces
//! (`leak`), instances (`instances`), alpha-masked casters (`masks`), ray origins at any scale (`origins`) and whole scenes rendered at any scale
//! (`scale`, on the GPU).

mod analytic;
mod indirect;
mod instances;
mod leak;
mod masks;
mod origins;
mod scale;
