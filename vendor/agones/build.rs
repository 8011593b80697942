// ledge's copy of the agones crate's build script (VENDORED.md): the same
// protocol definitions and the same tonic-build settings, but the .proto
// files are parsed by protox (pure Rust) instead of the `protoc` binary,
// so that building ledge needs nothing installed beyond Rust.
fn main() {
    let protos = [
        "proto/sdk/alpha/alpha.proto",
        "proto/sdk/beta/beta.proto",
        "proto/sdk/sdk.proto",
    ];
    let includes = [
        "proto/googleapis",
        "proto/grpc-gateway",
        "proto/sdk/alpha",
        "proto/sdk/beta",
        "proto/sdk",
    ];
    for path in protos.iter().chain(includes.iter()) {
        println!("cargo:rerun-if-changed={path}");
    }
    let descriptors =
        protox::compile(protos, includes).expect("failed to parse the Agones protocol buffers");
    tonic_build::configure()
        // The SDK is just a client, no need to build the server types
        .build_server(false)
        .compile_fds(descriptors)
        .expect("failed to compile protobuffers");
}
