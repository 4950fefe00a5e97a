#![no_main]
libfuzzer_sys::fuzz_target!(|input: kerf_fuzz::SurfaceCase| kerf_fuzz::normals(&input));
