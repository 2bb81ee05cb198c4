//! The live view (`run --live`): a WebSocket client speaking Foxglove's
//! protocol (the SDK's foxglove.sdk.v1) connects to a running computation,
//! subscribes to the scene and event channels and decodes what comes; the
//! run's recording is byte-identical with and without the live view.

use crate::common;
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, connect};

/// `knotrod ARGS --live 127.0.0.1:0`: the child and its port (read from the
/// line it prints before computing).
fn start_live(args: &[&str]) -> (std::process::Child, u16) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(args)
        .args(["--live", "127.0.0.1:0"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    let port = line
        .split("ws://127.0.0.1:")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no live address in {line:?}"));
    // the rest of standard error is drained, so the child never blocks on it
    std::thread::spawn(move || std::io::copy(&mut stderr, &mut std::io::sink()));
    (child, port)
}

/// A Foxglove WebSocket client (the SDK's protocol, foxglove.sdk.v1).
struct Client {
    ws: tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<std::net::TcpStream>>,
    /// Advertised channels by id.
    channels: std::collections::BTreeMap<u64, serde_json::Value>,
    /// The topics to subscribe to once advertised, in subscription order
    /// (subscription k + 1 is topic k).
    wanted: Vec<&'static str>,
    subscribed: bool,
}

impl Client {
    fn connect(port: u16, wanted: Vec<&'static str>) -> Client {
        let mut request = format!("ws://127.0.0.1:{port}")
            .into_client_request()
            .unwrap();
        request
            .headers_mut()
            .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
        let (ws, response) = connect(request).expect("the live view accepts a client");
        assert_eq!(
            response.headers()["Sec-WebSocket-Protocol"],
            "foxglove.sdk.v1"
        );
        if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
        }
        Client {
            ws,
            channels: Default::default(),
            wanted,
            subscribed: false,
        }
    }

    /// The advertised channel of `topic`.
    fn channel(&self, topic: &str) -> &serde_json::Value {
        self.channels
            .values()
            .find(|c| c["topic"] == topic)
            .unwrap_or_else(|| panic!("{topic} not advertised: {:?}", self.channels))
    }

    /// The next message on a subscribed topic: (topic index in `wanted`, its
    /// data); None once the server closes.
    fn next(&mut self) -> Option<(usize, Vec<u8>)> {
        loop {
            match self.ws.read().ok()? {
                Message::Text(text) => {
                    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
                    if v["op"] == "advertise" {
                        for c in v["channels"].as_array().unwrap() {
                            self.channels.insert(c["id"].as_u64().unwrap(), c.clone());
                        }
                    }
                    let all = self
                        .wanted
                        .iter()
                        .all(|w| self.channels.values().any(|c| c["topic"] == *w));
                    if !self.subscribed && all {
                        let subscriptions: Vec<serde_json::Value> = self
                            .wanted
                            .iter()
                            .enumerate()
                            .map(|(k, w)| {
                                serde_json::json!({"id": k + 1, "channelId": self.channel(w)["id"]})
                            })
                            .collect();
                        let subscribe = serde_json::json!({
                            "op": "subscribe",
                            "subscriptions": subscriptions,
                        });
                        self.ws.send(Message::text(subscribe.to_string())).unwrap();
                        self.subscribed = true;
                    }
                }
                // a message: opcode 1, subscription id (u32), time (u64), data
                Message::Binary(bytes) if bytes.first() == Some(&1) => {
                    let subscription = u32::from_le_bytes(bytes[1..5].try_into().unwrap());
                    return Some((subscription as usize - 1, bytes[13..].to_vec()));
                }
                _ => {}
            }
        }
    }
}

#[test]
fn a_foxglove_client_sees_the_running_computation() {
    let dir = common::temp_dir("live");
    let scene = "scenes/fig3_kirchhoff.toml";
    let live_record = dir.join("live.mcap");
    let record = live_record.to_str().unwrap();
    let (mut child, port) = start_live(&["run", scene, "--segments", "60", "--record", record]);
    let mut client = Client::connect(port, vec!["/rod/scene", "/events"]);
    let (mut scenes, mut events) = (Vec::new(), Vec::new());
    let start = Instant::now();
    while (scenes.is_empty() || events.is_empty()) && start.elapsed() < Duration::from_secs(60) {
        let Some((topic, data)) = client.next() else {
            break;
        };
        match topic {
            0 => scenes.push(
                <foxglove::messages::SceneUpdate as prost::Message>::decode(&data[..])
                    .expect("a foxglove.SceneUpdate"),
            ),
            _ => events.push(serde_json::from_slice::<serde_json::Value>(&data).unwrap()),
        }
    }
    // the server advertised the recording's channels and schemas
    assert_eq!(client.channels.len(), 5);
    assert_eq!(
        client.channel("/rod/scene")["schemaName"],
        "foxglove.SceneUpdate"
    );
    assert_eq!(client.channel("/events")["encoding"], "json");
    let _ = client.ws.close(None);
    let status = child.wait().unwrap();
    assert!(status.success(), "the live run failed");
    assert!(!scenes.is_empty(), "no scene came while the run computed");
    let rod = scenes[0]
        .entities
        .iter()
        .find(|e| e.id == "rod")
        .expect("the rod's entity");
    assert_eq!(rod.lines[0].points.len(), 62, "the centreline at N = 60");
    assert!(!events.is_empty(), "no event came while the run computed");
    assert!(events[0]["kind"].is_string() && events[0]["phi_over_2pi"].is_f64());
    // the recording does not know the live view was there
    let plain_record = dir.join("plain.mcap");
    common::knotrod_ok(&[
        "run",
        scene,
        "--segments",
        "60",
        "--record",
        plain_record.to_str().unwrap(),
    ]);
    assert!(
        std::fs::read(&live_record).unwrap() == std::fs::read(&plain_record).unwrap(),
        "the recording differs with --live"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_map_shows_its_lines_as_they_are_done() {
    // the Figure 7 island, 4 lines at N = 40: the boundary walk first, then
    // the lines in parallel, each sent as it is done
    let dir = common::temp_dir("live-map");
    let scene = crate::maps::small_map_scene(&dir);
    let json = dir.join("map.json");
    let (mut child, port) = start_live(&[
        "map",
        scene.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    let mut client = Client::connect(port, vec!["/map/points", "/map/lines"]);
    let (mut points, mut lines) = (0, Vec::new());
    while let Some((topic, data)) = client.next() {
        let v: serde_json::Value = serde_json::from_slice(&data).unwrap();
        if topic == 0 {
            assert!(v["along"].is_f64() && v["class"].is_string(), "{v}");
            points += 1;
        } else {
            lines.push(v);
        }
    }
    assert!(child.wait().unwrap().success(), "the live map failed");
    // every line came, with the intervals the map file holds
    let map: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(lines.len(), 4, "{lines:?}");
    assert!(points > 4 * 10, "{points} points");
    for l in &lines {
        let k = l["line"].as_u64().unwrap() as usize;
        assert_eq!(l["intervals"], map["lines"][k]["intervals"], "line {k}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_bad_live_address_is_refused_by_name() {
    let out = common::knotrod(&[
        "run",
        "scenes/appendix_d.toml",
        "--no-record",
        "--live",
        "localhost",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--live localhost: give HOST:PORT"));
}

#[test]
fn the_foxglove_layout_names_the_recorded_channels() {
    use knotrod::io::recording::{EVENTS_TOPIC, SCALARS_TOPIC, SCENE_TOPIC};
    let text = std::fs::read_to_string("recordings/knotrod.layout.json").unwrap();
    let layout: serde_json::Value = serde_json::from_str(&text).unwrap();
    let panels = layout["configById"].as_object().unwrap();
    assert!(panels["3D!knotrod"]["topics"][SCENE_TOPIC]["visible"] == true);
    assert_eq!(panels["3D!knotrod"]["followTf"], "rod");
    assert_eq!(panels["RawMessages!events"]["topicPath"], EVENTS_TOPIC);
    // every plotted path is a field of the scalars
    let fields = serde_json::to_value(knotrod::io::recording::Scalars {
        index: 0,
        branch: 0,
        leg: 0,
        z_star: 0.0,
        delta: 0.0,
        phi_over_2pi: 0.0,
        energy: 0.0,
        twist: 0.0,
        writhe: 0.0,
        link: 0.0,
        knot_determinant: 0,
        knotted: None,
        min_z: 0.0,
        max_z: 0.0,
        wall_distance: 0.0,
        min_self_distance: 0.0,
        lowest_eigenvalue: 0.0,
        lowest_omega_squared: 0.0,
        negative_eigenvalues: 0,
        stable: true,
        good_knot: true,
        iterations: 0,
        contact_force: 0.0,
    })
    .unwrap();
    let mut paths = Vec::new();
    for (name, panel) in panels.iter().filter(|(n, _)| n.starts_with("Plot!")) {
        for p in panel["paths"].as_array().unwrap() {
            paths.push((name.clone(), p["value"].as_str().unwrap().to_string()));
        }
        paths.push((
            name.clone(),
            panel["xAxisPath"]["value"].as_str().unwrap().to_string(),
        ));
    }
    assert!(paths.len() >= 5);
    for (panel, path) in paths {
        let field = path
            .strip_prefix(&format!("{SCALARS_TOPIC}."))
            .unwrap_or_else(|| panic!("{panel}: {path} is not a scalar"));
        assert!(fields.get(field).is_some(), "{panel}: no scalar {field}");
    }
    // every panel of the layout is configured, and every configured one placed
    let placed = layout["layout"].to_string();
    for name in panels.keys() {
        assert!(placed.contains(&format!("\"{name}\"")), "{name} not placed");
    }
}

#[test]
fn verify_shows_each_check_as_it_is_done() {
    // the Figure 3 branch's 100 shooting points: the first checks come while
    // the rest are computed; the test stops the run by its pid once it has
    // seen two
    let (mut child, port) = start_live(&[
        "verify",
        "scenes/verify/branch_100.csv",
        "--scene",
        "scenes/appendix_d.toml",
        "--segments",
        "40,80,160",
    ]);
    let mut client = Client::connect(port, vec!["/verify/checks"]);
    let mut checks = Vec::new();
    while checks.len() < 2 {
        let Some((_, data)) = client.next() else {
            break;
        };
        checks.push(serde_json::from_slice::<serde_json::Value>(&data).unwrap());
    }
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(checks.len(), 2, "two checks while the verification ran");
    for c in &checks {
        // as `verify --json` writes it: the given solution and the verdict
        assert!(c["given"]["name"].is_string(), "{c}");
        assert!(!c["verdict"].is_null(), "{c}");
        assert!(c["index"].as_u64().unwrap() < 100);
    }
}
