#![no_main]
libfuzzer_sys::fuzz_target!(|input: kerf_fuzz::MachineCase| kerf_fuzz::kinematics(&input));
