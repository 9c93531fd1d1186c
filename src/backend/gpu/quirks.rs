//! Driver behaviour the engine works around.
//!
//! lavapipe before Mesa 23 ("inlinable uniforms"): a compute pipeline whose shader branches or
//! loops on a value read from a uniform buffer is compiled again, with the buffer's values
//! inlined, every time it is bound for a dispatch, and every compiled copy is kept. Our
//! passes read `params` and `walls` as uniforms, so a run on Debian 12's stock Mesa 22.3
//! grew by about 0.36 MB per step (some 32 kB of compiled code per dispatch; measured with
//! heaptrack and VmRSS at N = 1000) and spent part of each step in LLVM. Mesa 23 keeps one
//! compiled variant per set of values instead, and Mesa 25 stays flat. There the engine
//! declares those two bindings as read-only storage (`Assembled::with_storage_uniforms`):
//! nothing is inlined, and the shaders compute the same bits.

/// Whether the driver recompiles, and keeps, a pipeline at every dispatch that reads uniforms
/// (lavapipe, i.e. `llvmpipe`, of a Mesa release before 23), from the adapter's driver name
/// and driver info ("Mesa 22.3.6 (LLVM 15.0.6)").
pub fn recompiles_per_dispatch_with_uniforms(driver: &str, driver_info: &str) -> bool {
    if driver != "llvmpipe" {
        return false;
    }
    let Some(version) = driver_info.strip_prefix("Mesa ") else {
        return false;
    };
    let major: String = version.chars().take_while(char::is_ascii_digit).collect();
    major.parse::<u32>().is_ok_and(|m| m < 23)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_lavapipe_before_mesa_23_is_affected() {
        assert!(recompiles_per_dispatch_with_uniforms(
            "llvmpipe",
            "Mesa 22.3.6 (LLVM 15.0.6)"
        ));
        assert!(recompiles_per_dispatch_with_uniforms(
            "llvmpipe",
            "Mesa 21.0.3"
        ));
        assert!(!recompiles_per_dispatch_with_uniforms(
            "llvmpipe",
            "Mesa 25.0.7-2~bpo12+1 (LLVM 19.1.7)"
        ));
        assert!(!recompiles_per_dispatch_with_uniforms(
            "llvmpipe",
            "Mesa 23.0.0"
        ));
        assert!(!recompiles_per_dispatch_with_uniforms(
            "NVIDIA",
            "550.54.14"
        ));
        assert!(!recompiles_per_dispatch_with_uniforms("llvmpipe", ""));
    }
}
