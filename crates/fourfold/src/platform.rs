//! The core's platform edge: the few things a native process and a web page do differently.
//! Everything else in the crate is the same code on both. (The other edge is the
//! `headless` module, declared for native targets only in `lib.rs`: drawing that waits for
//! the GPU, which a page cannot do.) A test checks that no other file of the core names a
//! target.

/// The longest formula accepted, in bytes: far beyond anything typed by hand, it bounds the
/// work (and the recursion) of every later stage. A web page's is shorter: it parses on the
/// browser's own stack (about 1 MB), where a native process has a thread with a large one
/// ([`with_large_stack`]).
#[cfg(not(target_arch = "wasm32"))]
pub const MAX_FORMULA_BYTES: usize = 64 * 1024;
#[cfg(target_arch = "wasm32")]
pub const MAX_FORMULA_BYTES: usize = 4 * 1024;

/// Stack for work that recurses once per bracket of a formula (reserved, not committed).
#[cfg(not(target_arch = "wasm32"))]
const LARGE_STACK: usize = 256 * 1024 * 1024;

/// Runs `work` on a thread with a large stack, so that no formula within
/// [`MAX_FORMULA_BYTES`] can overflow it; Err when that thread could not start or died. A
/// web page has no threads: there `work` runs in place.
#[cfg(not(target_arch = "wasm32"))]
pub fn with_large_stack<T: Send + 'static>(
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, String> {
    std::thread::Builder::new()
        .name("fourfold-parse".into())
        .stack_size(LARGE_STACK)
        .spawn(work)
        .map_err(|e| format!("could not start the parser thread: {e}"))?
        .join()
        .map_err(|_| "internal error while parsing".to_string())
}

#[cfg(target_arch = "wasm32")]
pub fn with_large_stack<T: Send + 'static>(
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, String> {
    Ok(work())
}

/// Runs `work`, which creates GPU objects, and returns what it made with the validation
/// error it caused, if any. Natively the error is waited for; a web page cannot wait, so
/// there the error goes to the log (the browser's console) when the GPU reports it, and
/// none is returned.
pub fn validated<T>(device: &wgpu::Device, work: impl FnOnce() -> T) -> (T, Option<wgpu::Error>) {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let made = work();
    #[cfg(not(target_arch = "wasm32"))]
    let error = pollster::block_on(scope.pop());
    #[cfg(target_arch = "wasm32")]
    let error = {
        let popped = scope.pop();
        wasm_bindgen_futures::spawn_local(async move {
            if let Some(error) = popped.await {
                log::error!("fourfold: {error}");
            }
        });
        None
    };
    (made, error)
}

/// The shader as wgpu takes it: natively the module naga has already parsed and validated
/// (wgpu does not parse the text again); in a page the text, which the browser compiles.
#[cfg(not(target_arch = "wasm32"))]
pub fn shader_source<'a>(_text: &'a str, module: &naga::Module) -> wgpu::ShaderSource<'a> {
    wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module.clone()))
}

#[cfg(target_arch = "wasm32")]
pub fn shader_source<'a>(text: &'a str, _module: &naga::Module) -> wgpu::ShaderSource<'a> {
    wgpu::ShaderSource::Wgsl(text.into())
}
