//! `knotrod::io::fuzz::curve_text` under libFuzzer.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| knotrod::io::fuzz::curve_text(data));
