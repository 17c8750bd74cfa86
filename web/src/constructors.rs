//! Running the module's static constructors, through which techniques register themselves
//! (`inventory`): the linker runs them before an export only when it judges the module to
//! be a command, which a wasm-bindgen library is not.
// The browser build's one unsafe code: a call into the linker's constructor function.
#![allow(unsafe_code)]

unsafe extern "C" {
    /// The module's static constructors, synthesised by the linker.
    fn __wasm_call_ctors();
}

/// Registers every linked technique; call it before anything reads the registry.
pub fn register_techniques() {
    // SAFETY: the function takes no arguments and runs the constructors the linker gathered:
    // inventory's registrations, which are idempotent.
    unsafe { __wasm_call_ctors() };
}
