//! `cargo run` at the workspace root opens the editor (the same as the `rt` binary).

fn main() -> std::process::ExitCode {
    rt_app::launch::main()
}
