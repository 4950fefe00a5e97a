#![no_main]
libfuzzer_sys::fuzz_target!(|input: kerf_fuzz::CurveCase| kerf_fuzz::discretize(&input));
