//! Builds the server side of the Agones SDK's gRPC services from the
//! definitions the SDK itself is built from (`vendor/agones/proto`, see
//! `vendor/agones/VENDORED.md`), parsed by protox: no `protoc` needed.

fn main() {
    let root = "../vendor/agones/proto";
    let protos = [
        format!("{root}/sdk/sdk.proto"),
        format!("{root}/sdk/beta/beta.proto"),
    ];
    let includes = [
        format!("{root}/googleapis"),
        format!("{root}/grpc-gateway"),
        format!("{root}/sdk/beta"),
        format!("{root}/sdk"),
    ];
    println!("cargo:rerun-if-changed={root}");
    let descriptors = protox::compile(&protos, &includes)
        .expect("parsing the Agones SDK protocol (vendor/agones/proto)");
    tonic_build::configure()
        .build_client(false)
        .build_server(true)
        .compile_fds(descriptors)
        .expect("generating the fake sidecar's gRPC services");
}
