//! `knotrod::io::fuzz::scene_text` under libFuzzer.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| knotrod::io::fuzz::scene_text(data));
