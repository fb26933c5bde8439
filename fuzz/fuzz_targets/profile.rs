#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| iktc_fuzz::profile(data));
