//! `knotrod::io::fuzz::recording_bytes` under libFuzzer.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| knotrod::io::fuzz::recording_bytes(data));
