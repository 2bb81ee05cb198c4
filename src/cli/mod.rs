//! The `knotrod` command line: the clap definitions and the dispatch. Each
//! command's body is in its own file.

mod knot;
mod map;
mod plot;
mod progress;
mod render;
mod reports;
mod run;
pub mod verify;

use crate::io::export::ExportFormat;
use anyhow::Result;
use clap::{Parser, Subcommand};
pub use knot::RayKind;
use std::path::PathBuf;

/// knotrod: equilibria and stability of clamped elastic rods.
#[derive(Parser, Debug)]
#[command(version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Solve a scene and print its equilibrium.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Write the JSON summary here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Override the scene's number of segments.
        #[arg(long)]
        segments: Option<usize>,
        /// Record to this MCAP file (default: recordings/<scene>.mcap).
        #[arg(long)]
        record: Option<PathBuf>,
        /// Do not record.
        #[arg(long, conflicts_with = "record")]
        no_record: bool,
        /// Serve the run live to the Foxglove app (WebSocket) at HOST:PORT
        /// (default 127.0.0.1:8765; port 0: any free port, printed).
        #[arg(long, num_args = 0..=1, default_missing_value = crate::io::live::DEFAULT_ADDRESS)]
        live: Option<String>,
        /// Run even when the predicted memory or CPU time exceeds `[budget]`.
        #[arg(long)]
        allow_large: bool,
    },
    /// Channels, states, parameter range and events of a recording.
    Info {
        /// The MCAP recording.
        recording: PathBuf,
    },
    /// One recorded state as a table (csv, json) or a tube mesh (obj).
    Export {
        /// The MCAP recording.
        recording: PathBuf,
        /// Index of the state.
        #[arg(long, default_value_t = 0)]
        index: u64,
        /// csv | json | obj | shooting | vtp | pvd (every state, --out NAME.pvd).
        #[arg(long, value_enum, default_value = "csv")]
        format: ExportFormat,
        /// Output file (default: stdout).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Pictures of configurations: the rod as a shaded tube with the yellow
    /// stripe along d1 (a strip as its ribbon), its clamps, rays and walls.
    Render {
        /// A recording (`.mcap`) or a `run --json` summary.
        input: PathBuf,
        /// The states, comma-separated, drawn side by side: indices in the
        /// run, `phi=V` (the state nearest φ/2π = V), or events by label (X,
        /// W1) or kind (contact_lost, fold:2): the state of the event's branch
        /// nearest it.
        #[arg(long, value_delimiter = ',', default_value = "0")]
        index: Vec<String>,
        /// Names written under the states (e.g. A,B as the paper's Figure 4),
        /// comma-separated, one per state (default: the event's label).
        #[arg(long, value_delimiter = ',')]
        label: Vec<String>,
        /// oblique | side | top | AZIMUTH,ELEVATION (degrees).
        #[arg(long, default_value = "oblique")]
        view: String,
        /// WIDTHxHEIGHT of the whole picture, pixels (default 1200x900 for
        /// one state, 800 wide per state for several).
        #[arg(long)]
        size: Option<String>,
        /// Width a strip is drawn with (default: its scene's strip_width, or
        /// 0.05 for a strip of zero width).
        #[arg(long)]
        strip_width: Option<f64>,
        /// The picture: NAME.png or NAME.svg.
        #[arg(long)]
        out: PathBuf,
    },
    /// Writhe and knot type of any curve (one "x y z" or "x,y,z" point per line).
    Knot {
        /// The curve file.
        curve: PathBuf,
        /// The curve is a closed loop (last point joins the first).
        #[arg(long)]
        closed: bool,
        /// How an open curve is closed: by rays along its end tangents, or
        /// along ∓z from the first and last points (the paper's closure).
        #[arg(long, value_enum, default_value = "tangent")]
        rays: RayKind,
        /// Write a JSON answer here ("-" for stdout).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Redraw the bifurcation diagram of a run's JSON summary or MCAP recording.
    Plot {
        /// The summary (`run --json`), recording (`.mcap`) or map file
        /// (`map --json`); several map files are drawn on one plane, the
        /// first's island as a region, the others' as curves.
        #[arg(required = true)]
        summary: Vec<PathBuf>,
        /// Output stem (default: the first file's path without extension).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Maps drawn on one plane: the name of each in the legend, once per
        /// map in order (default: their scenes').
        #[arg(long = "name")]
        names: Vec<String>,
        /// Maps drawn on one plane (one map too): a point to mark,
        /// NAME=SWEPT,ALONG (e.g. "photographed knot=0.17,0.78" for z*, φ/2π).
        #[arg(long)]
        mark: Option<String>,
        /// Maps drawn on one plane (one map too): the title.
        #[arg(long)]
        title: Option<String>,
    },
    /// Map the good-knot region: a branch in the continuation's parameter (φ for the
    /// paper's maps) per value of the map's parameter.
    Map {
        /// Scene with [continuation] (the branches) and [map] (the grid).
        scene: PathBuf,
        /// Write the map here (default recordings/<scene>.map.json).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Compute only shard i of n ("i/n") and write a partial result.
        #[arg(long)]
        shard: Option<String>,
        /// Override the scene's number of segments.
        #[arg(long)]
        segments: Option<usize>,
        /// Serve each line's points and intervals live to the Foxglove app
        /// (WebSocket) at HOST:PORT (default 127.0.0.1:8765; port 0: any free
        /// port, printed).
        #[arg(long, num_args = 0..=1, default_missing_value = crate::io::live::DEFAULT_ADDRESS)]
        live: Option<String>,
        /// Map even when the predicted memory or CPU time exceeds `[budget]`.
        #[arg(long)]
        allow_large: bool,
    },
    /// Join partial maps (from `map --shard`) into one map.
    Merge {
        /// Partial results.
        parts: Vec<PathBuf>,
        /// Write the map here.
        #[arg(long)]
        json: PathBuf,
    },
    /// Time the standard workloads and the growth of per-step costs with N.
    Bench {
        /// Folder holding the scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Also write the report as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Regenerate the validation report (docs/validation.md) on stdout.
    Validate {
        /// Folder holding the scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
    },
    /// Convergence study in N of a scene's equilibrium (markdown table).
    Convergence {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Segment counts, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "50,100,200,400,800")]
        segments: Vec<usize>,
        /// Run even when the predicted memory or CPU time exceeds `[budget]`.
        #[arg(long)]
        allow_large: bool,
    },
    /// Verify shooting solutions (TOML, JSON or CSV) by two independent
    /// methods: the continuum equations integrated adaptively and polished,
    /// and the discrete rod at N, 2N, 4N, Richardson-extrapolated.
    Verify(verify::Args),
}

/// Run the command line.
pub fn main_with(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run {
            scene,
            json,
            segments,
            record,
            no_record,
            live,
            allow_large,
        } => run::run(
            &scene,
            json,
            segments,
            if no_record { None } else { Some(record) },
            live.as_deref(),
            allow_large,
        ),
        Command::Info { recording } => Ok(crate::io::export::info(
            &recording,
            &mut std::io::stdout().lock(),
        )?),
        Command::Render {
            input,
            index,
            label,
            view,
            size,
            strip_width,
            out,
        } => render::render(
            &input,
            &index,
            &label,
            &view,
            size.as_deref(),
            strip_width,
            &out,
        ),
        Command::Export {
            recording,
            index,
            format,
            out,
        } => Ok(crate::io::export::export(
            &recording,
            index,
            format,
            out.as_deref(),
        )?),
        Command::Convergence {
            scene,
            segments,
            allow_large,
        } => reports::convergence(&scene, &segments, allow_large),
        Command::Verify(args) => verify::verify(args),
        Command::Knot {
            curve,
            closed,
            rays,
            json,
        } => knot::knot(&curve, closed, rays, json),
        Command::Plot {
            summary,
            out,
            names,
            mark,
            title,
        } => match summary.as_slice() {
            // a map's own options (--name, --mark, --title) draw it as the
            // maps are drawn together, never silently dropped
            [one] if names.is_empty() && mark.is_none() && title.is_none() => plot::plot(one, out),
            many => plot::overlay(many, out, &names, mark.as_deref(), title.as_deref()),
        },
        Command::Map {
            scene,
            json,
            shard,
            segments,
            live,
            allow_large,
        } => map::map(
            &scene,
            json,
            shard.as_deref(),
            segments,
            live.as_deref(),
            allow_large,
        ),
        Command::Merge { parts, json } => map::merge(&parts, &json),
        Command::Bench { scenes, json } => reports::bench(&scenes, json),
        Command::Validate { scenes } => reports::validate(&scenes),
    }
}
