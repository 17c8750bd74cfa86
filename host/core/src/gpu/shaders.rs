//! WGSL sources: embedded at build time, optionally read from disk, composed with `#import`.
//!
//! A line `#import "common/frame.wgsl"` is replaced by that file's text (each file is included
//! once per module); `enable` directives of any file (`enable wgpu_ray_query;`) move to the
//! top, where WGSL requires them. Errors are reported against the original file, line and
//! column.

use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;

mod embedded {
    include!(concat!(env!("OUT_DIR"), "/embedded_shaders.rs"));
}

/// A shader that failed to load, compose or validate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShaderError {
    /// No such file in the library.
    #[error("shader `{0}` not found")]
    NotFound(String),
    /// An `#import` could not be resolved.
    #[error("shaders/{file}:{line}: {message}")]
    Import {
        file: String,
        line: usize,
        message: String,
    },
    /// WGSL parsing or validation failed.
    #[error("shaders/{file}:{line}:{col}: {message}")]
    Compile {
        file: String,
        line: usize,
        col: usize,
        message: String,
    },
    /// wgpu rejected the module or pipeline.
    #[error("{label}: {message}")]
    Pipeline { label: String, message: String },
}

/// A composed WGSL module and where each of its lines came from.
#[derive(Debug, Clone)]
pub struct ComposedShader {
    pub name: String,
    pub source: String,
    /// For each line of `source` (0-based): (file, 1-based line in that file).
    line_map: Vec<(Arc<str>, usize)>,
}

impl ComposedShader {
    /// Moves `enable` directives (each once) before every declaration, keeping their origins.
    fn hoist_enable_directives(&mut self) {
        let mut enables: Vec<(&str, (Arc<str>, usize))> = Vec::new();
        let mut body = String::with_capacity(self.source.len());
        let mut body_map = Vec::with_capacity(self.line_map.len());
        for (line, origin) in self.source.lines().zip(&self.line_map) {
            if line.trim_start().starts_with("enable ") {
                if !enables.iter().any(|(e, _)| e.trim() == line.trim()) {
                    enables.push((line, origin.clone()));
                }
            } else {
                body.push_str(line);
                body.push('\n');
                body_map.push(origin.clone());
            }
        }
        if enables.is_empty() {
            return;
        }
        let mut source = String::with_capacity(self.source.len());
        let mut line_map = Vec::with_capacity(self.line_map.len());
        for (line, origin) in enables {
            source.push_str(line);
            source.push('\n');
            line_map.push(origin);
        }
        source.push_str(&body);
        line_map.extend(body_map);
        self.source = source;
        self.line_map = line_map;
    }

    /// Maps a 1-based line of the composed source back to (file, line).
    pub fn origin(&self, line: usize) -> (String, usize) {
        self.line_map
            .get(line.saturating_sub(1))
            .map(|(f, l)| (f.to_string(), *l))
            .unwrap_or_else(|| (self.name.clone(), line))
    }
}

/// Where shader sources come from.
#[derive(Debug, Clone, Default)]
pub struct ShaderLibrary {
    /// When set, files are read from this folder first (hot reload); embedded copies otherwise.
    disk_root: Option<PathBuf>,
}

impl ShaderLibrary {
    /// Sources compiled into the binary.
    pub fn embedded() -> ShaderLibrary {
        ShaderLibrary { disk_root: None }
    }

    /// Sources read from `root` when present there, embedded ones otherwise.
    pub fn from_disk(root: PathBuf) -> ShaderLibrary {
        ShaderLibrary {
            disk_root: Some(root),
        }
    }

    /// The `shaders/` folder this binary was built from, if it still exists.
    pub fn build_time_root() -> Option<PathBuf> {
        let root = PathBuf::from(embedded::SOURCE_ROOT).canonicalize().ok()?;
        root.is_dir().then_some(root)
    }

    /// Names of every embedded file.
    pub fn names() -> impl Iterator<Item = &'static str> {
        embedded::EMBEDDED.iter().map(|(n, _)| *n)
    }

    /// The folder files are read from first, if any.
    pub fn disk_root(&self) -> Option<&std::path::Path> {
        self.disk_root.as_deref()
    }

    /// Names of every file this library can load: the embedded ones and any `.wgsl` file under
    /// the disk folder (sorted, without duplicates).
    pub fn file_names(&self) -> Vec<String> {
        let mut names: Vec<String> = Self::names().map(str::to_string).collect();
        if let Some(root) = &self.disk_root {
            collect_wgsl(root, root, &mut names);
        }
        names.sort();
        names.dedup();
        names
    }

    /// The text of one file (or of a generated module, see [`crate::params::shader`]).
    pub fn source(&self, name: &str) -> Result<String, ShaderError> {
        if let Some(root) = &self.disk_root
            && let Ok(text) = std::fs::read_to_string(root.join(name))
        {
            return Ok(text);
        }
        embedded::EMBEDDED
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| s.to_string())
            .or_else(|| crate::params::shader::generated_shader(name))
            .ok_or_else(|| ShaderError::NotFound(name.to_string()))
    }

    /// Whether `name` is a shared module (no entry point: `common/` files, library filters
    /// that call functions their importer supplies). Such files are validated through the
    /// shaders that import them, not on their own.
    pub fn is_shared_module(&self, name: &str) -> bool {
        self.source(name).is_ok_and(|text| {
            !["@vertex", "@fragment", "@compute"]
                .iter()
                .any(|stage| text.contains(stage))
        })
    }

    /// Whether `name` imports a module of its own folder that neither a file nor a crate
    /// linked into this build provides: the generated module (`gpu_struct!`) of a plugin this
    /// build does not link, such as the example plugin's in the application. Such a shader
    /// cannot be composed here and no registered technique uses it.
    pub fn needs_unlinked_module(&self, name: &str) -> bool {
        let folder = |path: &str| path.split('/').next().map(str::to_string);
        self.source(name).is_ok_and(|text| {
            text.lines()
                .filter_map(|line| line.trim_start().strip_prefix("#import"))
                .map(|rest| rest.trim().trim_matches('"'))
                .any(|target| folder(target) == folder(name) && self.source(target).is_err())
        })
    }

    /// Resolves the imports of `name`.
    pub fn compose(&self, name: &str) -> Result<ComposedShader, ShaderError> {
        let text = self.source(name)?;
        self.compose_source(name, &text)
    }

    /// Resolves the imports of WGSL `text` that is not a file of the library (a technique's
    /// inline shader); errors in it are reported as `name:line:column`.
    pub fn compose_source(&self, name: &str, text: &str) -> Result<ComposedShader, ShaderError> {
        let mut out = ComposedShader {
            name: name.to_string(),
            source: String::new(),
            line_map: Vec::new(),
        };
        let mut seen = HashSet::from([name.to_string()]);
        self.append_text(name, text, &mut out, &mut seen, &mut Vec::new())?;
        out.hoist_enable_directives();
        Ok(out)
    }

    fn append(
        &self,
        name: &str,
        out: &mut ComposedShader,
        seen: &mut HashSet<String>,
        stack: &mut Vec<String>,
    ) -> Result<(), ShaderError> {
        if !seen.insert(name.to_string()) {
            return Ok(());
        }
        let text = self.source(name)?;
        self.append_text(name, &text, out, seen, stack)
    }

    fn append_text(
        &self,
        name: &str,
        text: &str,
        out: &mut ComposedShader,
        seen: &mut HashSet<String>,
        stack: &mut Vec<String>,
    ) -> Result<(), ShaderError> {
        let file: Arc<str> = Arc::from(name);
        stack.push(name.to_string());
        for (i, line) in text.lines().enumerate() {
            if let Some(rest) = line.trim_start().strip_prefix("#import") {
                let target = rest.trim().trim_matches('"');
                if stack.iter().any(|s| s == target) {
                    return Err(ShaderError::Import {
                        file: name.to_string(),
                        line: i + 1,
                        message: format!("`{target}` imports itself"),
                    });
                }
                self.append(target, out, seen, stack).map_err(|e| match e {
                    ShaderError::NotFound(_) => ShaderError::Import {
                        file: name.to_string(),
                        line: i + 1,
                        message: format!("cannot import `{target}`: no such shader"),
                    },
                    other => other,
                })?;
            } else {
                out.source.push_str(line);
                out.source.push('\n');
                out.line_map.push((file.clone(), i + 1));
            }
        }
        stack.pop();
        Ok(())
    }

    /// Composes and validates `name` with naga, reporting errors at their original location.
    pub fn validate(&self, name: &str) -> Result<(ComposedShader, naga::Module), ShaderError> {
        let (composed, module, _) = Self::validated(self.compose(name)?)?;
        Ok((composed, module))
    }

    /// Composes and validates WGSL `text` that is not a file of the library (see
    /// [`Self::compose_source`]).
    pub fn validate_source(
        &self,
        name: &str,
        text: &str,
    ) -> Result<(ComposedShader, naga::Module), ShaderError> {
        let (composed, module, _) = Self::validated(self.compose_source(name, text)?)?;
        Ok((composed, module))
    }

    /// Composes and validates `name`, with naga's analysis of it (which globals each entry
    /// point uses), for reflection.
    pub fn reflect(
        &self,
        name: &str,
    ) -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
        let (_, module, info) = Self::validated(self.compose(name)?)?;
        Ok((module, info))
    }

    fn validated(
        composed: ComposedShader,
    ) -> Result<(ComposedShader, naga::Module, naga::valid::ModuleInfo), ShaderError> {
        let module = naga::front::wgsl::parse_str(&composed.source).map_err(|e| {
            let location = e.location(&composed.source);
            compile_error(&composed, location, e.message().to_string())
        })?;
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        );
        let info = validator.validate(&module).map_err(|e| {
            let location = e.location(&composed.source);
            let mut message = e.as_inner().to_string();
            let mut source: Option<&dyn std::error::Error> =
                std::error::Error::source(e.as_inner());
            while let Some(inner) = source {
                message.push_str(": ");
                message.push_str(&inner.to_string());
                source = inner.source();
            }
            compile_error(&composed, location, message)
        })?;
        Ok((composed, module, info))
    }

    /// Creates a labelled shader module from `name`, validated first so errors carry locations.
    pub fn create_module(
        &self,
        device: &wgpu::Device,
        name: &str,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        Self::module_from(device, name, self.compose(name)?)
    }

    /// Creates a labelled shader module from WGSL `text` with `#import`s of the library (see
    /// [`Self::compose_source`]); `name` labels it and its errors.
    pub fn create_module_from_source(
        &self,
        device: &wgpu::Device,
        name: &str,
        text: &str,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        Self::module_from(device, name, self.compose_source(name, text)?)
    }

    /// Composes `name` (from WGSL `text` where given, else the library's file), validates it
    /// and creates its module, with naga's IR and analysis for reflection.
    pub fn load(
        &self,
        device: &wgpu::Device,
        name: &str,
        text: Option<&str>,
    ) -> Result<LoadedShader, ShaderError> {
        let composed = match text {
            Some(text) => self.compose_source(name, text)?,
            None => self.compose(name)?,
        };
        let (composed, ir, info) = Self::validated(composed)?;
        let module = Self::create_validated(device, name, composed)?;
        Ok(LoadedShader { module, ir, info })
    }

    fn module_from(
        device: &wgpu::Device,
        name: &str,
        composed: ComposedShader,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        let (composed, _, _) = Self::validated(composed)?;
        Self::create_validated(device, name, composed)
    }

    fn create_validated(
        device: &wgpu::Device,
        name: &str,
        composed: ComposedShader,
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        let (module, error) = super::context::validation_scope(device, || {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(composed.source.into()),
            })
        });
        match error {
            None => Ok(module),
            Some(e) => Err(ShaderError::Pipeline {
                label: name.to_string(),
                message: e.to_string(),
            }),
        }
    }
}

/// A shader module with naga's IR and analysis of it (which globals each entry point uses).
pub struct LoadedShader {
    pub module: wgpu::ShaderModule,
    pub ir: naga::Module,
    pub info: naga::valid::ModuleInfo,
}

/// Appends the `/`-separated paths of `.wgsl` files under `dir`, relative to `root`.
fn collect_wgsl(dir: &std::path::Path, root: &std::path::Path, out: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for path in entries.filter_map(Result::ok).map(|e| e.path()) {
        if path.is_dir() {
            collect_wgsl(&path, root, out);
        } else if path.extension().is_some_and(|e| e == "wgsl")
            && let Ok(relative) = path.strip_prefix(root)
        {
            out.push(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

fn compile_error(
    composed: &ComposedShader,
    location: Option<naga::SourceLocation>,
    message: String,
) -> ShaderError {
    let (line, col) = location
        .map(|l| (l.line_number as usize, l.line_position as usize))
        .unwrap_or((1, 1));
    let (file, line) = composed.origin(line);
    ShaderError::Compile {
        file,
        line,
        col,
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_point_into_the_imported_file() {
        let dir = std::env::temp_dir().join(format!("zoo-shaders-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("common")).unwrap();
        std::fs::write(
            dir.join("common/util.wgsl"),
            "fn ok() -> f32 { return 1.0; }\nfn bad() -> f32 { return missing; }\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("main.wgsl"),
            "// main\n#import \"common/util.wgsl\"\n@compute @workgroup_size(1) fn main() {}\n",
        )
        .unwrap();
        std::fs::write(dir.join("loop.wgsl"), "#import \"loop.wgsl\"\n").unwrap();
        std::fs::write(dir.join("missing.wgsl"), "\n#import \"common/nope.wgsl\"\n").unwrap();
        let library = ShaderLibrary::from_disk(dir);
        match library.validate("main.wgsl").unwrap_err() {
            ShaderError::Compile {
                file, line, col, ..
            } => assert_eq!((file.as_str(), line, col), ("common/util.wgsl", 2, 26)),
            other => panic!("unexpected {other}"),
        }
        let err = library.compose("loop.wgsl").unwrap_err().to_string();
        assert_eq!(err, "shaders/loop.wgsl:1: `loop.wgsl` imports itself");
        let err = library.compose("missing.wgsl").unwrap_err().to_string();
        assert_eq!(
            err,
            "shaders/missing.wgsl:2: cannot import `common/nope.wgsl`: no such shader"
        );
        // A missing import of another folder is an error to report, not an unlinked plugin's
        // own module.
        assert!(!library.needs_unlinked_module("missing.wgsl"));
        assert!(!library.needs_unlinked_module("main.wgsl"));
    }

    #[test]
    fn enable_directives_of_imports_go_first_once_and_errors_still_point_home() {
        let dir = std::env::temp_dir().join(format!("zoo-enable-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("lib")).unwrap();
        std::fs::write(
            dir.join("lib/half.wgsl"),
            "enable f16;\nfn half() -> f16 { return 1.0h; }\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("main.wgsl"),
            "// main\nconst one: f32 = 1.0;\n#import \"lib/half.wgsl\"\nenable f16;\n\
             @compute @workgroup_size(1) fn main() { let x = half() + missing; }\n",
        )
        .unwrap();
        let library = ShaderLibrary::from_disk(dir);
        let composed = library.compose("main.wgsl").unwrap();
        let lines: Vec<&str> = composed.source.lines().collect();
        assert_eq!(lines[0], "enable f16;");
        assert_eq!(lines.iter().filter(|l| l.starts_with("enable")).count(), 1);
        assert_eq!(composed.origin(1), ("lib/half.wgsl".to_string(), 1));
        assert_eq!(composed.origin(2), ("main.wgsl".to_string(), 1));
        // The module parses (the directive is before every declaration) and its error is
        // reported where it was written.
        match library.validate("main.wgsl").unwrap_err() {
            ShaderError::Compile { file, line, .. } => {
                assert_eq!((file.as_str(), line), ("main.wgsl", 5))
            }
            other => panic!("unexpected {other}"),
        }
    }

    /// The binary embeds the shaders of the checkout it was built in, as they are now: every
    /// `.wgsl` file of this checkout's `shaders/`, and no other (a build script that watched
    /// another checkout's absolute paths once kept serving stale copies after edits).
    #[test]
    fn embedded_shaders_are_this_checkout_s() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders");
        let root = root.canonicalize().unwrap();
        assert_eq!(ShaderLibrary::build_time_root(), Some(root.clone()));
        let mut on_disk = Vec::new();
        collect_wgsl(&root, &root, &mut on_disk);
        on_disk.sort();
        let mut embedded: Vec<String> = ShaderLibrary::names().map(str::to_string).collect();
        embedded.sort();
        assert_eq!(embedded, on_disk);
        for (name, source) in embedded::EMBEDDED {
            let file = std::fs::read_to_string(root.join(name)).unwrap();
            assert!(
                file == *source,
                "shaders/{name} differs from its embedded copy"
            );
        }
    }
}
