//! Recordings: every equilibrium of a run written to MCAP as it is computed,
//! with Foxglove's well-known schemas (protobuf `foxglove.SceneUpdate` and
//! `foxglove.FrameTransform`) for the 3D panel, a JSON channel of scalars for
//! plots, the full state for exact restarts, the events, and metadata. And the
//! way back: reading states, scalars and events from a recording.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::plot::class_colour;
use crate::model::rod::{RodModel, RodState};
use anyhow::{Context, Result, anyhow, bail};
use foxglove::Encode;
use foxglove::messages::{
    Color, CubePrimitive, FrameTransform, LinePrimitive, Point3, Pose, Quaternion, SceneEntity,
    SceneUpdate, Timestamp, Vector3 as FgVector3,
};
use mcap::records::{MessageHeader, Metadata};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Channel names.
pub const SCENE_TOPIC: &str = "/rod/scene";
/// Frame transform channel.
pub const TF_TOPIC: &str = "/tf";
/// Plot-friendly scalars.
pub const SCALARS_TOPIC: &str = "/rod/scalars";
/// Full state for restarts.
pub const STATE_TOPIC: &str = "/rod/state";
/// Located events.
pub const EVENTS_TOPIC: &str = "/events";

/// The scalars of one equilibrium (JSON on `/rod/scalars`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Scalars {
    /// Index of the state in the run.
    pub index: u64,
    /// Branch (or loading leg).
    pub branch: usize,
    /// Leg of the branch.
    pub leg: usize,
    /// z*.
    pub z_star: f64,
    /// δ.
    pub delta: f64,
    /// φ/2π.
    pub phi_over_2pi: f64,
    /// Elastic energy.
    pub energy: f64,
    /// Tw.
    pub twist: f64,
    /// Wr of the ray closure.
    pub writhe: f64,
    /// Tw + Wr.
    pub link: f64,
    /// |Δ(−1)|.
    pub knot_determinant: u64,
    /// Lowest interior z.
    pub min_z: f64,
    /// Highest interior z.
    pub max_z: f64,
    /// Wall clearance.
    #[serde(deserialize_with = "null_as_nan")]
    pub wall_distance: f64,
    /// Minimum self-distance.
    #[serde(deserialize_with = "null_as_nan")]
    pub min_self_distance: f64,
    /// Lowest Hessian eigenvalue.
    #[serde(deserialize_with = "null_as_nan")]
    pub lowest_eigenvalue: f64,
    /// Lowest ω².
    #[serde(deserialize_with = "null_as_nan")]
    pub lowest_omega_squared: f64,
    /// Negative eigenvalues.
    pub negative_eigenvalues: usize,
    /// Stable.
    pub stable: bool,
    /// Good knot.
    pub good_knot: bool,
    /// Newton/corrector iterations.
    pub iterations: usize,
    /// Total contact force.
    pub contact_force: f64,
}

/// JSON has no NaN or infinity: serde_json writes them as null (e.g. the wall
/// clearance of a rod with no interior extremum); read null back as NaN.
fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    use serde::Deserialize;
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Scalars {
    /// The scalars of an equilibrium.
    pub fn of(index: u64, e: &Equilibrium) -> Self {
        let nan_if_none = |v: Option<&f64>| v.copied().unwrap_or(f64::NAN);
        Scalars {
            index,
            branch: e.branch,
            leg: e.leg,
            z_star: e.z_star,
            delta: e.delta,
            phi_over_2pi: e.phi_over_2pi,
            energy: e.energy,
            twist: e.twist,
            writhe: e.writhe,
            link: e.link,
            knot_determinant: e.knot_determinant,
            min_z: e.min_z,
            max_z: e.max_z,
            wall_distance: e.wall_distance,
            min_self_distance: e.min_self_distance,
            lowest_eigenvalue: nan_if_none(e.lowest_eigenvalues.first()),
            lowest_omega_squared: nan_if_none(e.omega_squared.first()),
            negative_eigenvalues: e.negative_eigenvalues,
            stable: e.stable,
            good_knot: e.good_knot,
            iterations: e.iterations,
            contact_force: e.contact_force,
        }
    }
}

/// The full state message (JSON on `/rod/state`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StateMessage {
    /// Index of the state in the run.
    pub index: u64,
    /// The rod model.
    pub model: RodModel,
    /// The state.
    pub state: RodState,
}

const SCALARS_SCHEMA: &str = r#"{"title":"knotrod.Scalars","type":"object","properties":{"index":{"type":"integer"},"branch":{"type":"integer"},"leg":{"type":"integer"},"z_star":{"type":"number"},"delta":{"type":"number"},"phi_over_2pi":{"type":"number"},"energy":{"type":"number"},"twist":{"type":"number"},"writhe":{"type":"number"},"link":{"type":"number"},"knot_determinant":{"type":"integer"},"min_z":{"type":"number"},"max_z":{"type":"number"},"wall_distance":{"type":"number"},"min_self_distance":{"type":"number"},"lowest_eigenvalue":{"type":"number"},"lowest_omega_squared":{"type":"number"},"negative_eigenvalues":{"type":"integer"},"stable":{"type":"boolean"},"good_knot":{"type":"boolean"},"iterations":{"type":"integer"},"contact_force":{"type":"number"}}}"#;
const STATE_SCHEMA: &str = r#"{"title":"knotrod.RodState","type":"object","properties":{"index":{"type":"integer"},"model":{"type":"object"},"state":{"type":"object","properties":{"clamps":{"type":"object"},"nodes":{"type":"array"},"theta":{"type":"array"},"reference":{"type":"array"},"reference_twist":{"type":"array"}}}}}"#;
const EVENT_SCHEMA: &str = r#"{"title":"knotrod.Event","type":"object","properties":{"kind":{"type":"string"},"label":{"type":"string"},"phi_over_2pi":{"type":"number"},"z_star":{"type":"number"},"delta":{"type":"number"},"twist":{"type":"number"},"branch":{"type":"integer"},"detail":{"type":"string"}}}"#;

/// An MCAP recording being written. Call [`Recorder::finish`]: dropping it
/// unfinished leaves a file without its summary.
pub struct Recorder {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    path: PathBuf,
    channels: [u16; 5],
    count: u64,
    sequence: u32,
    rod_diameter: f64,
    model: RodModel,
}

fn fg_point(p: &nalgebra::Vector3<f64>) -> Point3 {
    Point3 {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

fn colour(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

fn identity_pose(at: nalgebra::Vector3<f64>) -> Pose {
    Pose {
        position: Some(FgVector3 {
            x: at.x,
            y: at.y,
            z: at.z,
        }),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }),
    }
}

fn encode<T: Encode>(m: &T) -> Result<Vec<u8>> {
    let mut buf = Vec::new();
    m.encode(&mut buf)
        .map_err(|e| anyhow!("encoding a Foxglove message: {e}"))?;
    Ok(buf)
}

impl Recorder {
    /// Create `path`, with metadata holding the scene text and versions.
    pub fn create(
        path: &Path,
        scene_text: &str,
        model: &RodModel,
        rod_diameter: f64,
    ) -> Result<Self> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let file =
            File::create(path).with_context(|| format!("creating recording {}", path.display()))?;
        let mut writer = mcap::WriteOptions::new()
            .profile("")
            .library(format!("knotrod {}", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))?;
        let mut channel = |topic: &str,
                           schema: Option<foxglove::Schema>,
                           json_title: &str,
                           json: &str|
         -> Result<u16> {
            let (name, encoding, data, msg_enc) = match schema {
                Some(s) => (s.name, s.encoding, s.data.into_owned(), "protobuf"),
                None => (
                    json_title.to_string(),
                    "jsonschema".to_string(),
                    json.as_bytes().to_vec(),
                    "json",
                ),
            };
            let sid = writer.add_schema(&name, &encoding, &data)?;
            Ok(writer.add_channel(sid, topic, msg_enc, &BTreeMap::new())?)
        };
        let channels = [
            channel(SCENE_TOPIC, SceneUpdate::get_schema(), "", "")?,
            channel(TF_TOPIC, FrameTransform::get_schema(), "", "")?,
            channel(SCALARS_TOPIC, None, "knotrod.Scalars", SCALARS_SCHEMA)?,
            channel(STATE_TOPIC, None, "knotrod.RodState", STATE_SCHEMA)?,
            channel(EVENTS_TOPIC, None, "knotrod.Event", EVENT_SCHEMA)?,
        ];
        let mut meta = BTreeMap::new();
        meta.insert("scene".to_string(), scene_text.to_string());
        meta.insert(
            "knotrod_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        );
        meta.insert(
            "git_revision".to_string(),
            env!("KNOTROD_GIT_REVISION").to_string(),
        );
        meta.insert("model".to_string(), serde_json::to_string(model)?);
        writer.write_metadata(&Metadata {
            name: "knotrod".into(),
            metadata: meta,
        })?;
        Ok(Recorder {
            writer: Some(writer),
            path: path.into(),
            channels,
            count: 0,
            sequence: 0,
            rod_diameter,
            model: model.clone(),
        })
    }

    /// Where it is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn write(&mut self, channel: usize, log_time: u64, data: &[u8]) -> Result<()> {
        let w = self
            .writer
            .as_mut()
            .ok_or_else(|| anyhow!("recording already finished"))?;
        self.sequence += 1;
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: self.channels[channel],
                sequence: self.sequence,
                log_time,
                publish_time: log_time,
            },
            data,
        )?;
        Ok(())
    }

    /// Record one equilibrium (log time = its index, in seconds).
    pub fn record(&mut self, e: &Equilibrium) -> Result<()> {
        let index = self.count;
        let t = index * 1_000_000_000;
        let stamp = Some(Timestamp::new(index as u32, 0));
        self.write(0, t, &encode(&scene_update(e, self.rod_diameter, stamp))?)?;
        let tf = FrameTransform {
            timestamp: stamp,
            parent_frame_id: "world".into(),
            child_frame_id: "rod".into(),
            translation: Some(FgVector3 {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            }),
            rotation: Some(Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            }),
        };
        self.write(1, t, &encode(&tf)?)?;
        self.write(2, t, &serde_json::to_vec(&Scalars::of(index, e))?)?;
        let state = StateMessage {
            index,
            model: self.model.clone(),
            state: e.state.clone(),
        };
        self.write(3, t, &serde_json::to_vec(&state)?)?;
        self.count += 1;
        Ok(())
    }

    /// Record the located events (at the time of the last state).
    pub fn events(&mut self, events: &[Event]) -> Result<()> {
        let t = self.count.saturating_sub(1) * 1_000_000_000;
        for e in events {
            self.write(4, t, &serde_json::to_vec(e)?)?;
        }
        Ok(())
    }

    /// Number of states recorded.
    pub fn len(&self) -> u64 {
        self.count
    }

    /// No state recorded yet.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Write the summary and close the file.
    pub fn finish(mut self) -> Result<()> {
        if let Some(mut w) = self.writer.take() {
            w.finish()
                .with_context(|| format!("finalising {}", self.path.display()))?;
        }
        Ok(())
    }
}

/// The Foxglove 3D scene of an equilibrium: the rod as a tube of its diameter
/// coloured like the paper's figures, d1 as short yellow segments, the clamps,
/// the rays and the two walls.
pub fn scene_update(e: &Equilibrium, diameter: f64, stamp: Option<Timestamp>) -> SceneUpdate {
    let c = class_colour(e);
    let rod_colour = colour(
        c.0 as f64 / 255.0,
        c.1 as f64 / 255.0,
        c.2 as f64 / 255.0,
        1.0,
    );
    let (points, _) = e.state.centreline();
    let entity = |id: &str| SceneEntity {
        timestamp: stamp,
        frame_id: "rod".into(),
        id: id.into(),
        frame_locked: true,
        ..Default::default()
    };
    let line = |kind: i32, pts: Vec<Point3>, thickness: f64, col: Color| LinePrimitive {
        r#type: kind,
        pose: Some(identity_pose(nalgebra::Vector3::zeros())),
        thickness,
        scale_invariant: false,
        points: pts,
        color: Some(col),
        ..Default::default()
    };
    let mut rod = entity("rod");
    rod.lines.push(line(
        0,
        points.iter().map(fg_point).collect(),
        diameter,
        rod_colour,
    ));
    // material frame: d1 at every edge midpoint, as the paper's yellow strip
    let n = e.state.segments();
    let len = 3.0 * diameter;
    let mut d1 = Vec::with_capacity(2 * n);
    for j in 1..n {
        let mid = 0.5 * (e.state.nodes[j] + e.state.nodes[j + 1]);
        let d = e.state.directors(j)[0];
        d1.push(fg_point(&mid));
        d1.push(fg_point(&(mid + len * d)));
    }
    let mut frame = entity("d1");
    frame
        .lines
        .push(line(2, d1, 0.3 * diameter, colour(0.95, 0.8, 0.1, 1.0)));
    let z_star = e.z_star;
    let end = e.state.clamps.end_point();
    let mut clamps = entity("clamps");
    let reach = 0.3;
    for at in [nalgebra::Vector3::zeros(), end] {
        clamps.cubes.push(CubePrimitive {
            pose: Some(identity_pose(at)),
            size: Some(FgVector3 {
                x: 2.0 * diameter,
                y: 2.0 * diameter,
                z: 4.0 * diameter,
            }),
            color: Some(colour(0.3, 0.3, 0.3, 1.0)),
        });
    }
    let grey = colour(0.5, 0.5, 0.5, 0.6);
    let mut rays = entity("rays");
    rays.lines.push(line(
        0,
        vec![
            fg_point(&nalgebra::Vector3::zeros()),
            Point3 {
                x: 0.0,
                y: 0.0,
                z: -reach,
            },
        ],
        diameter,
        grey,
    ));
    rays.lines.push(line(
        0,
        vec![
            fg_point(&end),
            Point3 {
                x: end.x,
                y: end.y,
                z: end.z + reach,
            },
        ],
        diameter,
        grey,
    ));
    let mut walls = entity("walls");
    for z in [0.0, z_star] {
        walls.cubes.push(CubePrimitive {
            pose: Some(identity_pose(nalgebra::Vector3::new(0.0, 0.0, z))),
            size: Some(FgVector3 {
                x: 0.5,
                y: 0.5,
                z: 0.0005,
            }),
            color: Some(colour(0.6, 0.7, 0.9, 0.15)),
        });
    }
    // contact points: red cubes whose size grows with the force
    let mut contacts = entity("contacts");
    let (_, arc) = e.state.centreline();
    let largest = e.contacts.iter().map(|c| c.force).fold(0.0, f64::max);
    for c in &e.contacts {
        let k = arc.partition_point(|a| *a <= c.s).clamp(1, arc.len() - 1);
        let t = ((c.s - arc[k - 1]) / (arc[k] - arc[k - 1]).max(1e-300)).clamp(0.0, 1.0);
        let at = points[k - 1] + t * (points[k] - points[k - 1]);
        let size = diameter * (1.5 + 2.0 * c.force / largest.max(1e-300));
        contacts.cubes.push(CubePrimitive {
            pose: Some(identity_pose(at)),
            size: Some(FgVector3 {
                x: size,
                y: size,
                z: size,
            }),
            color: Some(colour(0.9, 0.1, 0.1, 0.9)),
        });
    }
    SceneUpdate {
        deletions: vec![],
        entities: vec![rod, frame, clamps, rays, walls, contacts],
    }
}

/// What a recording holds.
#[derive(Debug, Default)]
pub struct Recording {
    /// Scalars of every state, in order.
    pub scalars: Vec<Scalars>,
    /// Events.
    pub events: Vec<Event>,
    /// Metadata (scene text, versions).
    pub metadata: BTreeMap<String, String>,
    /// Topics and their message counts.
    pub channels: BTreeMap<String, u64>,
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("cannot read recording {}", path.display()))
}

/// Read scalars, events, metadata and channel counts of a recording.
pub fn read_recording(path: &Path) -> Result<Recording> {
    let bytes = read_bytes(path)?;
    let bad =
        |e: mcap::McapError| anyhow!("{}: not a readable MCAP recording ({e})", path.display());
    let mut rec = Recording::default();
    for m in mcap::MessageStream::new(&bytes).map_err(bad)? {
        let m = m.map_err(bad)?;
        *rec.channels.entry(m.channel.topic.clone()).or_insert(0) += 1;
        match m.channel.topic.as_str() {
            SCALARS_TOPIC => rec.scalars.push(
                serde_json::from_slice(&m.data)
                    .with_context(|| format!("{}: malformed scalars message", path.display()))?,
            ),
            EVENTS_TOPIC => rec.events.push(
                serde_json::from_slice(&m.data)
                    .with_context(|| format!("{}: malformed event message", path.display()))?,
            ),
            _ => {}
        }
    }
    for r in mcap::read::LinearReader::new(&bytes).map_err(bad)? {
        if let mcap::records::Record::Metadata(md) = r.map_err(bad)?
            && md.name == "knotrod"
        {
            rec.metadata = md.metadata;
        }
    }
    Ok(rec)
}

/// The state with index `index` of a recording, with its model.
pub fn read_state(path: &Path, index: u64) -> Result<StateMessage> {
    let bytes = read_bytes(path)?;
    let bad =
        |e: mcap::McapError| anyhow!("{}: not a readable MCAP recording ({e})", path.display());
    let mut count = 0;
    for m in mcap::MessageStream::new(&bytes).map_err(bad)? {
        let m = m.map_err(bad)?;
        if m.channel.topic == STATE_TOPIC {
            count += 1;
            let s: StateMessage = serde_json::from_slice(&m.data)
                .with_context(|| format!("{}: malformed state message", path.display()))?;
            if s.index == index {
                return Ok(s);
            }
        }
    }
    bail!(
        "{}: no state with index {index} ({count} states recorded)",
        path.display()
    )
}
