//! GLSL to SPIR-V with shaderc (glslang). Sources are embedded at build time from glsl/
//! (or read from `FLUIDFORM_GLSL_DIR` when set, to edit shaders without rebuilding);
//! `#include "common/x.glsl"` resolves against the glsl/ root or the including file.
use super::interface::Reflected;
use crate::error::{Error, Result};
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

include!(concat!(env!("OUT_DIR"), "/glsl_sources.rs"));

/// Every embedded GLSL file, by path relative to glsl/.
pub fn glsl_files() -> impl Iterator<Item = &'static str> {
    GLSL_SOURCES.iter().map(|(p, _)| *p)
}

/// The text of glsl/`path`.
pub fn glsl_source(path: &str) -> Result<Cow<'static, str>> {
    // (Generated headers exist only in the build: always the embedded ones.)
    let generated = path.starts_with("generated/");
    if let Some(dir) = std::env::var("FLUIDFORM_GLSL_DIR")
        .ok()
        .filter(|_| !generated)
    {
        let full = std::path::Path::new(&dir).join(path);
        return std::fs::read_to_string(&full)
            .map(Cow::Owned)
            .map_err(|e| Error::Io {
                path: full.display().to_string(),
                source: e,
            });
    }
    GLSL_SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| Cow::Borrowed(*s))
        .ok_or_else(|| Error::Io {
            path: format!("glsl/{path}"),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        })
}

/// Shader stage from the file extension.
pub fn stage_of(path: &str) -> Result<shaderc::ShaderKind> {
    use shaderc::ShaderKind as K;
    Ok(match path.rsplit('.').next().unwrap_or("") {
        "comp" => K::Compute,
        "vert" => K::Vertex,
        "frag" => K::Fragment,
        "geom" => K::Geometry,
        "tesc" => K::TessControl,
        "tese" => K::TessEvaluation,
        "glsl" => K::InferFromSource,
        other => {
            return Err(Error::Param(format!(
                "glsl/{path}: unknown shader extension '.{other}'"
            )))
        }
    })
}

type Key = (String, Vec<(String, String)>);

fn key(path: &str, defines: &[(&str, String)]) -> Key {
    (
        path.to_string(),
        defines
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect(),
    )
}

/// Compiles and caches SPIR-V per (file, defines).
pub struct ShaderCompiler {
    compiler: Mutex<shaderc::Compiler>,
    cache: Mutex<HashMap<Key, Arc<Vec<u32>>>>,
    declared: Mutex<HashMap<Key, Arc<Reflected>>>,
}

impl ShaderCompiler {
    pub fn new() -> Result<Self> {
        let compiler = shaderc::Compiler::new()
            .map_err(|e| Error::Unsupported(format!("shaderc: cannot create compiler: {e}")))?;
        Ok(Self {
            compiler: Mutex::new(compiler),
            cache: Mutex::new(HashMap::new()),
            declared: Mutex::new(HashMap::new()),
        })
    }

    /// Compile glsl/`path` with `#define NAME VALUE` for each define.
    pub fn compile(&self, path: &str, defines: &[(&str, String)]) -> Result<Arc<Vec<u32>>> {
        let key = key(path, defines);
        if let Some(spv) = self.cache.lock().unwrap().get(&key) {
            return Ok(spv.clone());
        }
        let source = glsl_source(path)?;
        let spv = Arc::new(self.compile_source(path, &source, stage_of(path)?, defines)?);
        self.cache.lock().unwrap().insert(key, spv.clone());
        Ok(spv)
    }

    /// Compile a source string; `name` (relative to glsl/) is used for includes and errors.
    pub fn compile_source(
        &self,
        name: &str,
        source: &str,
        kind: shaderc::ShaderKind,
        defines: &[(&str, String)],
    ) -> Result<Vec<u32>> {
        self.compile_at(
            name,
            source,
            kind,
            defines,
            shaderc::OptimizationLevel::Performance,
        )
    }

    /// What glsl/`path` declares (bindings, push constants), from an unoptimized compile:
    /// the optimizer drops bindings a shader declares but does not use, and a pipeline is
    /// checked against everything its GLSL declares (gpu/interface.rs).
    pub fn declared(&self, path: &str, defines: &[(&str, String)]) -> Result<Arc<Reflected>> {
        let key = key(path, defines);
        if let Some(r) = self.declared.lock().unwrap().get(&key) {
            return Ok(r.clone());
        }
        let source = glsl_source(path)?;
        let spv = self.compile_at(
            path,
            &source,
            stage_of(path)?,
            defines,
            shaderc::OptimizationLevel::Zero,
        )?;
        let r = Arc::new(super::interface::reflect(path, &spv)?);
        self.declared.lock().unwrap().insert(key, r.clone());
        Ok(r)
    }

    fn compile_at(
        &self,
        name: &str,
        source: &str,
        kind: shaderc::ShaderKind,
        defines: &[(&str, String)],
        level: shaderc::OptimizationLevel,
    ) -> Result<Vec<u32>> {
        // Kept on disk between processes of this binary (gpu/cache.rs), unless the GLSL is
        // read from FLUIDFORM_GLSL_DIR, whose includes may change under it.
        let kept = std::env::var_os("FLUIDFORM_GLSL_DIR")
            .is_none()
            .then(|| {
                let key = (name, source, defines, level as u32, kind as u32);
                super::cache::spirv_path(super::cache::build_id(), &key)
            })
            .flatten();
        if let Some(words) = kept.as_deref().and_then(super::cache::load_spirv) {
            return Ok(words);
        }
        let mut opts = shaderc::CompileOptions::new()
            .map_err(|e| Error::Unsupported(format!("shaderc options: {e}")))?;
        opts.set_target_env(
            shaderc::TargetEnv::Vulkan,
            shaderc::EnvVersion::Vulkan1_2 as u32,
        );
        opts.set_target_spirv(shaderc::SpirvVersion::V1_5);
        opts.set_optimization_level(level);
        opts.set_generate_debug_info();
        for (k, v) in defines {
            opts.add_macro_definition(k, Some(v));
        }
        opts.set_include_callback(|requested, ty, requester, _depth| {
            let candidates = match ty {
                shaderc::IncludeType::Relative => {
                    let dir = requester.rsplit_once('/').map(|(d, _)| d).unwrap_or("");
                    let dir = dir.strip_prefix("glsl/").unwrap_or(dir);
                    vec![join(dir, requested), requested.to_string()]
                }
                shaderc::IncludeType::Standard => vec![requested.to_string()],
            };
            for c in &candidates {
                if let Ok(text) = glsl_source(c) {
                    return Ok(shaderc::ResolvedInclude {
                        resolved_name: format!("glsl/{c}"),
                        content: text.into_owned(),
                    });
                }
            }
            Err(format!("cannot find include \"{requested}\" in glsl/"))
        });
        let file = format!("glsl/{name}");
        let compiler = self.compiler.lock().unwrap();
        let words = compiler
            .compile_into_spirv(source, kind, &file, "main", Some(&opts))
            .map(|a| a.as_binary().to_vec())
            .map_err(|e| parse_error(&file, &e.to_string()))?;
        if let Some(p) = &kept {
            super::cache::save_spirv(p, &words);
        }
        Ok(words)
    }
}

/// `dir/rel` with "." and ".." resolved (paths stay inside glsl/).
fn join(dir: &str, rel: &str) -> String {
    let mut parts: Vec<&str> = dir.split('/').filter(|p| !p.is_empty()).collect();
    for p in rel.split('/') {
        match p {
            "" | "." => {}
            ".." => {
                parts.pop();
            }
            _ => parts.push(p),
        }
    }
    parts.join("/")
}

/// Turn glslang's "file:line: error: text" into an error naming file and line.
fn parse_error(file: &str, text: &str) -> Error {
    for l in text.lines() {
        if let Some((loc, msg)) = l.split_once(": error: ") {
            if let Some((f, line)) = loc.rsplit_once(':') {
                if let Ok(line) = line.trim().parse() {
                    return Error::Shader {
                        file: f.trim().to_string(),
                        line,
                        message: msg.trim().to_string(),
                    };
                }
            }
        }
    }
    Error::Shader {
        file: file.to_string(),
        line: 0,
        message: text.trim().to_string(),
    }
}
