//! Builds the server side of the Agones SDK's gRPC services from the
//! vendored definitions (`proto/`, see its README). Needs `protoc`
//! (Debian: protobuf-compiler), as the `agones` crate itself does.

fn main() {
    tonic_build::configure()
        .build_client(false)
        .build_server(true)
        .compile_protos(
            &["proto/sdk/sdk.proto", "proto/sdk/beta/beta.proto"],
            &[
                "proto/googleapis",
                "proto/grpc-gateway",
                "proto/sdk/beta",
                "proto/sdk",
            ],
        )
        .expect(
            "compiling the Agones SDK protocol (proto/): is protoc installed? \
             (apt-get install protobuf-compiler)",
        );
}
