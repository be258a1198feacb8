//! Reading a scene (a file or standard input, within the size limit) and compiling it, its
//! errors rendered with line and column.

use std::io::{self, Read};

use mechgen::syntax::limits::Limits;

use crate::args::Input;
use crate::diagnostics;
use crate::failure::{Failure, failed, read_failure};

/// A scene's text and the name its errors are reported under.
pub(crate) struct Source {
    pub(crate) name: String,
    pub(crate) text: String,
}

/// Reads a scene, at most `limits.bytes` of it: a larger file is refused before it is read
/// (by its size), a larger standard input once the limit is passed.
pub(crate) fn read_source(input: &Input, limits: &Limits) -> Result<Source, Failure> {
    let (name, reader, size): (String, Box<dyn Read>, Option<u64>) = match input {
        Input::Stdin => ("<stdin>".to_owned(), Box::new(io::stdin()), None),
        Input::File(path) => {
            let name = path.display().to_string();
            let file = std::fs::File::open(path).map_err(|e| read_failure(&name, &e))?;
            let size = file
                .metadata()
                .ok()
                .filter(|m| m.is_file())
                .map(|m| m.len());
            (name, Box::new(file), size)
        }
    };
    let limit = u64::try_from(limits.bytes).unwrap_or(u64::MAX);
    if let Some(size) = size.filter(|&size| size > limit) {
        return Err(too_large(&name, &size.to_string(), limits));
    }
    let mut bytes = Vec::new();
    reader
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| read_failure(&name, &e))?;
    if bytes.len() > limits.bytes {
        return Err(too_large(
            &name,
            &format!("more than {}", limits.bytes),
            limits,
        ));
    }
    let text = String::from_utf8(bytes)
        .map_err(|e| read_failure(&name, &io::Error::new(io::ErrorKind::InvalidData, e)))?;
    Ok(Source { name, text })
}

fn too_large(name: &str, size: &str, limits: &Limits) -> Failure {
    failed(format_args!(
        "`{name}` is {size} bytes, more than the {} bytes mechgen reads (`--max-file-size`, \
         default {})\n  hint: pass `--max-file-size BYTES` to read a larger scene (checking \
         takes about 2 s and 70 MB per 100 000 statements); scenes this \
         large are better built in code with `mechgen::builder`",
        limits.bytes,
        mechgen::syntax::limits::MAX_SOURCE_BYTES
    ))
}

/// Reads the scene's text within `limits` (statement by statement) and compiles it.
pub(crate) fn compile(source: &Source, limits: &Limits) -> Result<mechgen::Scene, Failure> {
    let read = mechgen::syntax::source::read(&source.text, limits);
    read.spec
        .map_err(mechgen::Errors::from)
        .and_then(|spec| {
            mechgen::compile(mechgen::Input::Spec(&spec), &mechgen::Options::default())
        })
        .map_err(|errors| {
            Failure::Failed(diagnostics::render(
                &source.name,
                &source.text,
                &read.locations,
                &errors,
            ))
        })
}
