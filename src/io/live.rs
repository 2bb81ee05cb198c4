//! The live view (`--live`): a Foxglove WebSocket server (the `foxglove`
//! SDK's) publishing a run's channels as it computes them — the same
//! channels, schemas and messages as its recording (`/rod/scene`, `/tf`,
//! `/rod/scalars`, `/rod/state`, `/events`), so the Foxglove app's 3D panel
//! and plots show the rod, the scalars and the events while they come. The
//! server has a context of its own: nothing else logs to it, and the
//! recording is written as without it. A map's live view (`map --live`)
//! sends each line's points and intervals as the line is done, and
//! `verify --live` each solution's check.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use crate::io::recording::writer::{ChannelSpec, channel_specs, state_messages};
use crate::model::rod::RodModel;
use foxglove::{Context, PartialMetadata, RawChannel, WebSocketServer, WebSocketServerHandle};
use std::path::Path;
use std::sync::Arc;

/// Where the live view listens unless told: loopback, Foxglove's port.
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:8765";

/// A failure of the live view, named by its address.
fn failed(address: &str, reason: String) -> IoError {
    IoError::Recording {
        path: format!("--live {address}").into(),
        reason,
    }
}

/// `HOST:PORT`, the port 0 for any free one.
pub fn parse_address(address: &str) -> Result<(String, u16)> {
    let bad = || {
        failed(
            address,
            "give HOST:PORT, e.g. 127.0.0.1:8765 (port 0: any free port)".into(),
        )
    };
    let (host, port) = address.rsplit_once(':').ok_or_else(bad)?;
    let port: u16 = port.parse().map_err(|_| bad())?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host.is_empty() {
        return Err(bad());
    }
    Ok((host.to_string(), port))
}

/// A Foxglove WebSocket server and its channels, in a context of its own.
struct Server {
    handle: WebSocketServerHandle,
    /// The context the server and channels live in (they hold it weakly:
    /// without this, clients would be greeted and nothing advertised).
    _context: Arc<Context>,
    channels: Vec<Arc<RawChannel>>,
}

impl Server {
    /// Serve `specs`' channels at `address`.
    fn start(address: &str, specs: Vec<ChannelSpec>) -> Result<Server> {
        let (host, port) = parse_address(address)?;
        let ctx = Context::new();
        let mut channels = Vec::new();
        for spec in specs {
            let channel = ctx
                .channel_builder(spec.topic)
                .message_encoding(spec.message_encoding)
                .schema(spec.schema)
                .build_raw()
                .map_err(|e| failed(address, format!("channel {}: {e}", spec.topic)))?;
            channels.push(channel);
        }
        let handle = WebSocketServer::new()
            .name(format!("knotrod {}", env!("CARGO_PKG_VERSION")))
            .context(&ctx)
            .bind(host, port)
            .start_blocking()
            .map_err(|e| failed(address, format!("cannot serve: {e}")))?;
        Ok(Server {
            handle,
            _context: ctx,
            channels,
        })
    }

    /// Send `data` on channel `k` at log time `index` seconds.
    fn send(&self, k: usize, data: &[u8], index: u64) {
        self.channels[k].log_with_meta(data, at(index));
    }

    /// Stop, once what was sent has gone out to the clients.
    fn stop(self) {
        self.handle.stop().wait_blocking();
    }
}

/// `value` as JSON bytes for the live view.
fn json<T: serde::Serialize>(step: &'static str, value: &T) -> Result<Vec<u8>> {
    serde_json::to_vec(value).map_err(IoError::json(step, Path::new("the live view")))
}

/// A running live view of a run.
pub struct Live {
    server: Server,
    model: RodModel,
    rod_diameter: f64,
    count: u64,
}

impl Live {
    /// Start serving at `address` (`HOST:PORT`) the states of `model`'s rod
    /// of diameter `rod_diameter`.
    pub fn start(address: &str, model: &RodModel, rod_diameter: f64) -> Result<Live> {
        Ok(Live {
            server: Server::start(address, channel_specs().into())?,
            model: model.clone(),
            rod_diameter,
            count: 0,
        })
    }

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.server.handle.port()
    }

    /// Publish an equilibrium (log time = its index in seconds, as recorded).
    pub fn equilibrium(&mut self, e: &Equilibrium) -> Result<()> {
        let index = self.count;
        let messages = state_messages(
            index,
            e,
            &self.model,
            self.rod_diameter,
            Path::new("the live view"),
        )?;
        for (k, data) in messages.iter().enumerate() {
            self.server.send(k, data, index);
        }
        self.count += 1;
        Ok(())
    }

    /// Publish an event (at the time of the last state).
    pub fn event(&self, e: &Event) -> Result<()> {
        let data = json("encoding an event", e)?;
        self.server.send(4, &data, self.count.saturating_sub(1));
        Ok(())
    }

    /// Publish the run's events with their final labels (at its end: as
    /// located, their labels were provisional).
    pub fn final_events(&self, events: &[Event]) -> Result<()> {
        events.iter().try_for_each(|e| self.event(e))
    }

    /// Stop serving, once what was published has gone out to the clients.
    pub fn stop(self) {
        self.server.stop();
    }
}

/// The points of the map's lines as they are computed (`/map/points`).
pub const MAP_POINTS_TOPIC: &str = "/map/points";
/// Each finished line: its good intervals (`/map/lines`).
pub const MAP_LINES_TOPIC: &str = "/map/lines";

const MAP_POINT_SCHEMA: &str = r#"{"title":"knotrod.MapPoint","type":"object","properties":{"line":{"type":"integer"},"value":{"type":"number"},"along":{"type":"number"},"twist":{"type":"number"},"class":{"type":"string"},"good":{"type":"boolean"}}}"#;
const MAP_LINE_SCHEMA: &str = r#"{"title":"knotrod.MapLine","type":"object","properties":{"line":{"type":"integer"},"value":{"type":"number"},"intervals":{"type":"array"},"error":{"type":"string"}}}"#;

/// One point of a map's line, as the live view sends it.
#[derive(serde::Serialize)]
struct MapPoint {
    line: usize,
    value: f64,
    along: f64,
    twist: f64,
    class: crate::analysis::class::Class,
    good: bool,
}

/// A finished line, as the live view sends it.
#[derive(serde::Serialize)]
struct MapLine<'a> {
    line: usize,
    value: f64,
    intervals: &'a [crate::study::map::Interval],
    error: Option<&'a str>,
}

/// A running live view of a map: each line's points and intervals as the
/// line is done (in Foxglove, a Plot of `/map/points.value` against
/// `/map/points.along` draws the island as it fills in).
pub struct LiveMap {
    server: Server,
}

impl LiveMap {
    /// Start serving at `address`.
    pub fn start(address: &str) -> Result<LiveMap> {
        let spec = |topic, name: &str, schema: &'static str| ChannelSpec {
            topic,
            schema: foxglove::Schema::new(name, "jsonschema", schema.as_bytes()),
            message_encoding: "json",
        };
        Ok(LiveMap {
            server: Server::start(
                address,
                vec![
                    spec(MAP_POINTS_TOPIC, "knotrod.MapPoint", MAP_POINT_SCHEMA),
                    spec(MAP_LINES_TOPIC, "knotrod.MapLine", MAP_LINE_SCHEMA),
                ],
            )?,
        })
    }

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.server.handle.port()
    }

    /// Publish a finished line (log time: its index in seconds).
    pub fn line(&self, l: &crate::study::map::Line) -> Result<()> {
        let at = l.index as u64;
        for p in &l.points {
            let point = MapPoint {
                line: l.index,
                value: l.value,
                along: p.along,
                twist: p.twist,
                class: p.class,
                good: p.class == crate::analysis::class::Class::Good,
            };
            self.server
                .send(0, &json("encoding a map point", &point)?, at);
        }
        let line = MapLine {
            line: l.index,
            value: l.value,
            intervals: &l.intervals,
            error: l.error.as_deref(),
        };
        self.server
            .send(1, &json("encoding a map line", &line)?, at);
        Ok(())
    }

    /// Stop serving, once what was published has gone out to the clients.
    pub fn stop(self) {
        self.server.stop();
    }
}

/// The log time of state `index`: `index` seconds.
fn at(index: u64) -> PartialMetadata {
    PartialMetadata {
        log_time: Some(index * 1_000_000_000),
    }
}

/// Each verified solution, as `verify --json` writes it (`/verify/checks`).
pub const VERIFY_TOPIC: &str = "/verify/checks";

const CHECK_SCHEMA: &str = r#"{"title":"knotrod.SolutionCheck","type":"object","properties":{"index":{"type":"integer"},"given":{"type":"object"},"verdict":{"type":"string"}}}"#;

/// A running live view of `verify`: each solution's check as it is done.
pub struct LiveChecks {
    server: Server,
}

impl LiveChecks {
    /// Start serving at `address`.
    pub fn start(address: &str) -> Result<LiveChecks> {
        let spec = ChannelSpec {
            topic: VERIFY_TOPIC,
            schema: foxglove::Schema::new(
                "knotrod.SolutionCheck",
                "jsonschema",
                CHECK_SCHEMA.as_bytes(),
            ),
            message_encoding: "json",
        };
        Ok(LiveChecks {
            server: Server::start(address, vec![spec])?,
        })
    }

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.server.handle.port()
    }

    /// Publish a solution's check (log time: its index in seconds).
    pub fn check(&self, c: &crate::study::verify::SolutionCheck) -> Result<()> {
        let data = json("encoding a check", c)?;
        self.server.send(0, &data, c.index as u64);
        Ok(())
    }

    /// Stop serving, once what was published has gone out to the clients.
    pub fn stop(self) {
        self.server.stop();
    }
}
