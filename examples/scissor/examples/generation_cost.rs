//! How generation cost grows with scene size: for the scissor lift at n stages, the time to
//! build the spec text, expand it (`mechgen::expand`), turn the tokens into source text
//! as `write_to_out_dir` does (and optionally format them with prettyplease, for comparison), and the release compile time of the generated code in a scratch
//! crate.
//!
//! ```text
//! cargo run --release -p mechgen-scissor --example generation_cost -- \
//!     [--stages 10,100,1000] [--max-function-size N] [--no-compile] [--pretty] [--timeout SECS]
//! ```
//!
//! Each n gets a crate under `target/scissor-compile/n{N}` depending on `mechgen-runtime` by path
//! (default features off) and including the generated file. All of them share one target
//! directory, `target/scissor-compile/target`, in which a trivial crate is built first, so the
//! runtime and its dependencies are compiled once and excluded from every per-n time; each n's
//! own crate is cleaned before it is timed. This takes minutes and is not part of
//! `cargo test`.

#[path = "../scene.rs"]
mod scene;
// `scene.rs` finds the dimensions at `crate::geometry`, as in the build script.
use mechgen_scissor::geometry;

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

struct Options {
    stages: Vec<usize>,
    codegen: mechgen::CodegenOptions,
    compile: bool,
    pretty: bool,
    timeout: Duration,
}

fn parse_args() -> Result<Options, String> {
    let mut options = Options {
        stages: vec![10, 100, 1000],
        codegen: mechgen::CodegenOptions::default(),
        compile: true,
        pretty: false,
        timeout: Duration::from_secs(1800),
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--stages" => {
                options.stages = value("--stages")?
                    .split(',')
                    .map(|s| match s.trim().parse::<usize>() {
                        Ok(n) if n >= 1 => Ok(n),
                        _ => Err(format!("--stages: {s:?} is not a whole number ≥ 1")),
                    })
                    .collect::<Result<_, _>>()?;
            }
            "--max-function-size" => {
                let text = value("--max-function-size")?;
                options.codegen.max_function_size = text
                    .parse()
                    .map_err(|_| format!("--max-function-size: {text:?} is not a number"))?;
            }
            "--timeout" => {
                let text = value("--timeout")?;
                let secs: u64 = text
                    .parse()
                    .map_err(|_| format!("--timeout: {text:?} is not a number of seconds"))?;
                options.timeout = Duration::from_secs(secs);
            }
            "--no-compile" => options.compile = false,
            "--pretty" => options.pretty = true,
            other => {
                return Err(format!(
                    "unknown argument {other:?}; expected --stages LIST, --max-function-size N, \
                     --no-compile, --pretty or --timeout SECS"
                ));
            }
        }
    }
    Ok(options)
}

/// One row of the report.
struct Row {
    stages: usize,
    bodies: usize,
    coordinates: usize,
    spec_bytes: usize,
    generated_bytes: usize,
    functions: usize,
    largest_function: usize,
    build: Duration,
    expand: Duration,
    to_text: Duration,
    pretty: Option<Duration>,
    compile: Option<Result<Duration, String>>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let options = parse_args()?;
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let workspace = workspace.canonicalize()?;
    let root = workspace.join("target/scissor-compile");
    let target_dir = root.join("target");
    if options.compile {
        eprintln!("building the runtime once (not counted) …");
        let warmup = write_crate(&root, &workspace, "warmup", "")?;
        let time = cargo_build(&warmup, &target_dir, options.timeout)?;
        eprintln!("  {:.1} s", time.as_secs_f64());
        // A rebuild of the trivial crate: the fixed cost in every per-n time below.
        let baseline = timed_compile(&warmup, &target_dir, "warmup", options.timeout)?;
        eprintln!(
            "fixed cost of one crate build (trivial crate): {:.2} s",
            baseline.as_secs_f64()
        );
    }
    let mut rows = Vec::new();
    for &stages in &options.stages {
        eprintln!("n = {stages} …");
        let start = Instant::now();
        let builder = scene::scissor_lift(stages);
        let spec = builder.build()?;
        let build = start.elapsed();

        let start = Instant::now();
        let tokens = mechgen::expand(
            mechgen::Input::Text(&spec),
            &mechgen::Options {
                limits: mechgen::Limits::UNBOUNDED_SIZE,
                codegen: options.codegen,
            },
        )?;
        let expand = start.elapsed();

        // What `write_to_out_dir` writes: one statement per line (see `source_text`).
        let start = Instant::now();
        let code = mechgen::builder::source_text(tokens.clone());
        let to_text = start.elapsed();

        let pretty = options.pretty.then(|| {
            let start = Instant::now();
            let formatted = mechgen::pretty(tokens.clone());
            let time = start.elapsed();
            drop(formatted);
            time
        });
        let (functions, largest_function) = function_sizes(tokens.clone());
        let compile = if options.compile {
            let name = format!("n{stages}");
            let krate = write_crate(&root, &workspace, &name, &code)?;
            Some(
                timed_compile(&krate, &target_dir, &name, options.timeout)
                    .map_err(|e| e.to_string()),
            )
        } else {
            None
        };
        let coordinates = 6 * stages + geometry::EXTRA_COORDINATES;
        let row = Row {
            stages,
            bodies: coordinates / 3,
            coordinates,
            spec_bytes: spec.len(),
            generated_bytes: code.len(),
            functions,
            largest_function,
            build,
            expand,
            to_text,
            pretty,
            compile,
        };
        eprintln!("{}", format_row(&row));
        rows.push(row);
    }
    println!(
        "max_function_size = {}\n",
        options.codegen.max_function_size
    );
    println!("{}", header());
    for row in &rows {
        println!("{}", format_row(row));
    }
    Ok(())
}

fn header() -> String {
    "| n | bodies | coordinates | spec bytes | generated bytes | fns | largest fn (tokens) | build s | expand s | text s | pretty s | release compile s |\n\
     |---|---|---|---|---|---|---|---|---|---|---|---|"
        .to_owned()
}

fn format_row(row: &Row) -> String {
    let mut line = format!(
        "| {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | ",
        row.stages,
        row.bodies,
        row.coordinates,
        row.spec_bytes,
        row.generated_bytes,
        row.functions,
        row.largest_function,
        row.build.as_secs_f64(),
        row.expand.as_secs_f64(),
        row.to_text.as_secs_f64(),
    );
    match row.pretty {
        Some(time) => {
            let _ = write!(line, "{:.3} | ", time.as_secs_f64());
        }
        None => line.push_str("– | "),
    }
    match &row.compile {
        Some(Ok(time)) => {
            let _ = write!(line, "{:.1} |", time.as_secs_f64());
        }
        Some(Err(error)) => {
            let _ = write!(line, "{error} |");
        }
        None => line.push_str("– |"),
    }
    line
}

/// Number of `fn` items with a body (accessors included) and the most tokens in one body: what
/// rustc's per-function cost depends on.
fn function_sizes(tokens: TokenStream) -> (usize, usize) {
    // Iterative walk; `fn` followed (at the same level) by a brace group is a function body.
    let (mut count, mut largest) = (0, 0);
    let mut stack = vec![tokens.into_iter()];
    let mut after_fn = Vec::new();
    after_fn.push(false);
    while let Some(top) = stack.last_mut() {
        let Some(token) = top.next() else {
            stack.pop();
            after_fn.pop();
            continue;
        };
        let level = after_fn.len() - 1;
        match token {
            TokenTree::Ident(ident) if ident == "fn" => after_fn[level] = true,
            TokenTree::Punct(p) if p.as_char() == ';' => after_fn[level] = false,
            TokenTree::Group(group) => {
                if after_fn[level] && group.delimiter() == Delimiter::Brace {
                    after_fn[level] = false;
                    count += 1;
                    largest = largest.max(token_count(group.stream()));
                }
                stack.push(group.stream().into_iter());
                after_fn.push(false);
            }
            _ => {}
        }
    }
    (count, largest)
}

fn token_count(tokens: TokenStream) -> usize {
    let mut count = 0;
    let mut stack = vec![tokens.into_iter()];
    while let Some(top) = stack.last_mut() {
        match top.next() {
            None => {
                stack.pop();
            }
            Some(TokenTree::Group(group)) => {
                count += 1;
                stack.push(group.stream().into_iter());
            }
            Some(_) => count += 1,
        }
    }
    count
}

/// Writes (or rewrites) the scratch crate `root/name` including `code`; returns its directory.
fn write_crate(
    root: &Path,
    workspace: &Path,
    name: &str,
    code: &str,
) -> Result<PathBuf, Box<dyn Error>> {
    let dir = root.join(name);
    std::fs::create_dir_all(dir.join("src"))?;
    let runtime = workspace.join("runtime");
    let manifest = format!(
        "[package]\nname = \"scissor-{name}\"\nversion = \"0.0.0\"\nedition = \"2024\"\npublish = false\n\n\
         [dependencies]\nmechgen-runtime = {{ path = {:?}, default-features = false }}\n\n\
         # Not part of the mechgen workspace this directory sits in.\n[workspace]\n",
        runtime.display().to_string()
    );
    std::fs::write(dir.join("Cargo.toml"), manifest)?;
    // The workspace's lock file pins the same dependency versions as the real build.
    std::fs::copy(workspace.join("Cargo.lock"), dir.join("Cargo.lock"))?;
    std::fs::write(dir.join("src/scissor.rs"), code)?;
    std::fs::write(
        dir.join("src/lib.rs"),
        "//! Generated scissor lift, included as a build script's output would be.\n\
         #![no_std]\n\
         include!(\"scissor.rs\");\n",
    )?;
    Ok(dir)
}

/// Cleans the crate's own artifacts, then times its release build.
fn timed_compile(
    krate: &Path,
    target_dir: &Path,
    name: &str,
    timeout: Duration,
) -> Result<Duration, Box<dyn Error>> {
    // Others may be editing the runtime: rebuild it here, untimed, if it changed.
    let warmup = krate.with_file_name("warmup");
    cargo_build(&warmup, target_dir, timeout)?;
    let status = Command::new(cargo())
        .args(["clean", "--release", "--offline", "--quiet", "-p"])
        .arg(format!("scissor-{name}"))
        .current_dir(krate)
        .env("CARGO_TARGET_DIR", target_dir)
        .status()?;
    if !status.success() {
        return Err(format!("cargo clean failed in {}", krate.display()).into());
    }
    cargo_build(krate, target_dir, timeout)
}

/// `cargo build --release` in `krate`, timed; stopped after `timeout`.
fn cargo_build(
    krate: &Path,
    target_dir: &Path,
    timeout: Duration,
) -> Result<Duration, Box<dyn Error>> {
    let mut command = Command::new(cargo());
    command
        .args(["build", "--release", "--offline", "--quiet"])
        .current_dir(krate)
        .env("CARGO_TARGET_DIR", target_dir);
    // Its own process group, so that a timeout stops rustc too, not only cargo.
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut command, 0);
    let start = Instant::now();
    let mut child = command.spawn()?;
    loop {
        if let Some(status) = child.try_wait()? {
            let elapsed = start.elapsed();
            return if status.success() {
                Ok(elapsed)
            } else {
                Err(format!("cargo build failed in {}", krate.display()).into())
            };
        }
        if start.elapsed() > timeout {
            #[cfg(unix)]
            let _ = Command::new("kill")
                .args(["-KILL", &format!("-{}", child.id())])
                .status();
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("> {} s (stopped)", timeout.as_secs()).into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The cargo running this example, if known.
fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned())
}
