//! `knotrod::io::fuzz::knot_points` under libFuzzer.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| knotrod::io::fuzz::knot_points(data));
