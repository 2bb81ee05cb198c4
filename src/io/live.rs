//! The live view (`--live`): a Foxglove WebSocket server (the `foxglove`
//! SDK's) publishing a run's channels as it computes them — the same
//! channels, schemas and messages as its recording (`/rod/scene`, `/tf`,
//! `/rod/scalars`, `/rod/state`, `/events`), so the Foxglove app's 3D panel
//! and plots show the rod, the scalars and the events while they come. The
//! server has a context of its own: nothing else logs to it, and the
//! recording is written as without it.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use crate::io::recording::writer::{channel_specs, state_messages};
use crate::model::rod::RodModel;
use foxglove::{Context, PartialMetadata, RawChannel, WebSocketServer, WebSocketServerHandle};
use std::path::Path;
use std::sync::Arc;

/// Where the live view listens unless told: loopback, Foxglove's port.
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:8765";

/// A running live view.
pub struct Live {
    server: WebSocketServerHandle,
    /// The context the server and channels live in (they hold it weakly:
    /// without this, clients would be greeted and nothing advertised).
    _context: Arc<Context>,
    /// The channels, in the order of the recording's.
    channels: Vec<Arc<RawChannel>>,
    model: RodModel,
    rod_diameter: f64,
    count: u64,
}

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

impl Live {
    /// Start serving at `address` (`HOST:PORT`) the states of `model`'s rod
    /// of diameter `rod_diameter`.
    pub fn start(address: &str, model: &RodModel, rod_diameter: f64) -> Result<Live> {
        let (host, port) = parse_address(address)?;
        let ctx = Context::new();
        let mut channels = Vec::new();
        for spec in channel_specs() {
            let channel = ctx
                .channel_builder(spec.topic)
                .message_encoding(spec.message_encoding)
                .schema(spec.schema)
                .build_raw()
                .map_err(|e| failed(address, format!("channel {}: {e}", spec.topic)))?;
            channels.push(channel);
        }
        let server = WebSocketServer::new()
            .name(format!("knotrod {}", env!("CARGO_PKG_VERSION")))
            .context(&ctx)
            .bind(host, port)
            .start_blocking()
            .map_err(|e| failed(address, format!("cannot serve: {e}")))?;
        Ok(Live {
            server,
            _context: ctx,
            channels,
            model: model.clone(),
            rod_diameter,
            count: 0,
        })
    }

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.server.port()
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
        for (channel, data) in self.channels.iter().zip(&messages) {
            channel.log_with_meta(data, at(index));
        }
        self.count += 1;
        Ok(())
    }

    /// Publish an event (at the time of the last state).
    pub fn event(&self, e: &Event) -> Result<()> {
        let data = serde_json::to_vec(e).map_err(IoError::json(
            "encoding an event",
            Path::new("the live view"),
        ))?;
        self.channels[4].log_with_meta(&data, at(self.count.saturating_sub(1)));
        Ok(())
    }

    /// Publish the run's events with their final labels (at its end: as
    /// located, their labels were provisional).
    pub fn final_events(&self, events: &[Event]) -> Result<()> {
        events.iter().try_for_each(|e| self.event(e))
    }

    /// Stop serving, once what was published has gone out to the clients.
    pub fn stop(self) {
        self.server.stop().wait_blocking();
    }
}

/// The log time of state `index`: `index` seconds.
fn at(index: u64) -> PartialMetadata {
    PartialMetadata {
        log_time: Some(index * 1_000_000_000),
    }
}
