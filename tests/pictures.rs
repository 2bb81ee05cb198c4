//! Pictures of configurations (`knotrod render`): the tube lands where the
//! projection puts it, a strip is drawn as its ribbon, states are picked by
//! index, φ and event, and bad requests are refused by name.

use crate::common;
use image::Rgb;
use knotrod::io::render::{Body, Picture, View, pixel_of, png, svg};
use knotrod::model::rod::{Clamps, RodState};
use nalgebra::Vector3;

/// A straight rod from the origin to (−0.3, 0, 0.8), d1 along x.
fn straight(ribbon: Option<f64>) -> Body {
    Body {
        state: RodState::straight(40, Clamps::new(0.8, 0.3, 0.0)),
        diameter: 0.02,
        ribbon,
        colour: [40, 160, 60],
        label: String::new(),
        caption: String::new(),
        contacts: vec![],
    }
}

/// Painted (not the white ground): between the walls, seen edge-on from the
/// side, only the rod is drawn (the rays and clamps lie beyond the walls).
fn on_rod(p: &Rgb<u8>) -> bool {
    p.0.iter().any(|&c| c < 235)
}

/// The columns of `row` where the rod is drawn.
fn rod_columns(img: &image::RgbImage, row: u32) -> Vec<u32> {
    (0..img.width())
        .filter(|&c| on_rod(img.get_pixel(c, row)))
        .collect()
}

/// Draw `body` from the side and check, at heights along the rod, that the
/// row crosses it centred where the projection puts its centreline, as wide
/// as `width` (in the rod's units) seen across a row.
fn drawn_where_projected(body: Body, width: f64) {
    let picture = Picture {
        width: 600,
        height: 450,
        view: View::SIDE,
    };
    let bodies = [body];
    let bytes = png(&bodies, &picture).unwrap();
    let img = image::load_from_memory(&bytes).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (600, 450));
    let end = bodies[0].state.clamps.end_point();
    let at = |p: Vector3<f64>| pixel_of(&bodies, &picture, 0, &p).unwrap();
    // pixels per unit length, and the rod's slant: a row meets it over
    // width / cos(its angle to the vertical)
    let scale = (at(Vector3::x()).0 - at(Vector3::zeros()).0) as f64;
    assert!(
        scale > 100.0,
        "the rod fills the picture: {scale} px per unit"
    );
    let across = width * scale * end.norm() / end.z;
    for s in [0.25, 0.4, 0.5, 0.6, 0.75] {
        let (x, y) = at(end * s);
        let hits = rod_columns(&img, y.round() as u32);
        assert!(!hits.is_empty(), "s = {s}: no rod in row {y}");
        let (lo, hi) = (hits[0] as f64, *hits.last().unwrap() as f64 + 1.0);
        let centre = 0.5 * (lo + hi);
        assert!(
            (centre - x as f64).abs() < 1.5,
            "s = {s}: drawn at x = {centre}, projected at {x}"
        );
        assert!(
            (hi - lo - across).abs() < 0.1 * across + 2.0,
            "s = {s}: {} px wide, expected {across:.1}",
            hi - lo
        );
    }
    // not blank, and nothing of the rod far from it
    let far = rod_columns(&img, at(end * 0.5).1.round() as u32)
        .into_iter()
        .filter(|&c| (c as f32 - at(end * 0.5).0).abs() > across as f32)
        .count();
    assert_eq!(far, 0);
}

#[test]
fn a_tube_is_drawn_where_the_projection_puts_it() {
    drawn_where_projected(straight(None), 0.02);
}

#[test]
fn a_strip_is_drawn_as_its_ribbon_seen_face_on() {
    // d1 along x lies in the picture's plane: the ribbon is seen face-on
    drawn_where_projected(straight(Some(0.1)), 0.1);
}

#[test]
fn the_svg_holds_the_same_faces_as_the_png() {
    let picture = Picture {
        width: 400,
        height: 300,
        view: View::OBLIQUE,
    };
    let mut body = straight(None);
    body.label = "A & B".into();
    body.caption = "good knot\nφ/2π = 0".into();
    let text = svg(&[body], &picture);
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    // the visible faces of the tube, the clamps, the rays and the two walls
    assert!(text.matches("<polygon").count() > 500);
    assert!(text.contains(">A &amp; B: good knot</text>"));
    assert!(text.contains("fill-opacity"), "the walls are translucent");
}

#[test]
fn views_and_sizes_are_read_or_refused_by_name() {
    assert_eq!(View::parse("side").unwrap(), View::SIDE);
    let v = View::parse("-30, 45").unwrap();
    assert_eq!((v.azimuth, v.elevation), (-30.0, 45.0));
    for bad in ["sideways", "10", "10,100", "nan,0"] {
        assert!(View::parse(bad).unwrap_err().contains("--view"), "{bad}");
    }
    assert_eq!(Picture::parse_size("800x600").unwrap(), (800, 600));
    for bad in ["800", "0x600", "9000x10", "axb"] {
        assert!(
            Picture::parse_size(bad).unwrap_err().contains("--size"),
            "{bad}"
        );
    }
    // the screen's axes are right-handed: right × up = towards the viewer
    let [r, u, t] = View::OBLIQUE.axes();
    assert!((r.cross(&u) - t).norm() < 1e-12);
}

#[test]
fn render_picks_states_by_index_phi_and_event() {
    let dir = common::temp_dir("render");
    let sample = "recordings/samples/fig3_n60.mcap";
    let png_out = dir.join("fig5.png");
    let out = common::knotrod(&[
        "render",
        sample,
        "--index",
        "phi=0.88,X",
        "--label",
        "left,X",
        "--out",
        png_out.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = image::open(&png_out).unwrap().to_rgb8();
    // two states side by side: 800 pixels wide each by default
    assert_eq!(img.dimensions(), (1600, 900));
    let svg_out = dir.join("w.svg");
    common::knotrod_ok(&[
        "render",
        sample,
        "--index",
        "W1,5",
        "--view",
        "top",
        "--out",
        svg_out.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg_out).unwrap();
    assert!(text.contains(">W1: "), "the event's label names the state");
    // an unknown event names the ones there are; a bad extension its field
    let out = common::knotrod(&["render", sample, "--index", "Q7", "--out", "x.png"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("Q7") && err.contains("W2, X"), "{err}");
    for (args, field) in [
        (vec!["--index", "0", "--out", "x.jpg"], "--out"),
        (vec!["--index", "999", "--out", "x.png"], "--index 999"),
        (
            vec!["--index", "0,1", "--label", "A", "--out", "x.png"],
            "--label",
        ),
        (
            vec!["--index", "0", "--view", "up", "--out", "x.png"],
            "--view",
        ),
        (vec!["--index", "phi=x", "--out", "x.png"], "phi="),
    ] {
        let mut all = vec!["render", sample];
        all.extend(args);
        let out = common::knotrod(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(field),
            "{all:?}: {err}"
        );
    }
    assert!(!std::path::Path::new("x.png").exists());
    std::fs::remove_dir_all(dir).unwrap();
}
