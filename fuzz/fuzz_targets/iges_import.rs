#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| kerf_fuzz::iges_import(data));
