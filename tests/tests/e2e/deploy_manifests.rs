//! The Kubernetes manifests of `deploy/agones/` (docs/DEPLOY.md), checked
//! without a cluster:
//!
//! - every manifest against its kind's schema: Agones' own CRD schemas for
//!   GameServer, Fleet and FleetAutoscaler (the OpenAPI v3 schemas the API
//!   server validates with, Agones v1.60.0, from `shared/testdata/agones`
//!   beside the repository: `deploy/agones/schema/README.md`), and ours for
//!   GameServerAllocation, which is no CRD (`deploy/agones/schema/`).
//!   Unknown fields are errors, as with `kubectl apply` (strict field
//!   validation): a misspelt key fails here instead of being dropped;
//! - broken copies of them (a wrong type, an unknown enum value, a
//!   misspelt key, a missing field) are rejected, each where it was broken;
//! - what no schema knows: the Fleet runs the GameServer's spec; that spec
//!   declares the Counters and List the server reports, with the capacities
//!   its flags give (parsed by the server's own command line); its port is
//!   the one the image exposes and listens on; the allocations and the
//!   autoscaler name that Fleet and those Counters.
//!
//! `LEDGE_AGONES_SCHEMAS=DIR` reads Agones' schemas from DIR instead.
//! Agones' schemas are other people's files, which this repository does
//! not hold; when they are not beside it, the manifests of those three
//! kinds are checked by everything but their schemas, and the tests say
//! so loudly on stderr.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::Parser;
use jsonschema::Validator;
use ledge_server::config::Cli;
use ledge_shared::protocol::{check_text, MAX_ID_LEN};
use serde::Deserialize;
use serde_json::{json, Value};

const DEPLOY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy");
const AGONES_SCHEMAS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/testdata/agones");

/// The manifests the guide applies, by file name.
const MANIFESTS: [&str; 5] = [
    "allocation-any-room.yaml",
    "allocation-named-room.yaml",
    "fleet.yaml",
    "fleetautoscaler.yaml",
    "gameserver.yaml",
];

/// What the server reports through the Agones SDK (`docs/DEPLOY.md`, "What
/// the server reports"): Counters, then Lists.
const COUNTERS: [&str; 2] = ["rooms", "players"];
const LISTS: [&str; 1] = ["rooms"];

fn agones_schemas() -> PathBuf {
    std::env::var_os("LEDGE_AGONES_SCHEMAS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(AGONES_SCHEMAS))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The one YAML document of `deploy/agones/NAME`.
fn manifest(name: &str) -> Value {
    let path = Path::new(DEPLOY).join("agones").join(name);
    let text = read(&path);
    let mut docs = serde_norway::Deserializer::from_str(&text)
        .map(|d| Value::deserialize(d).unwrap_or_else(|e| panic!("{}: {e}", path.display())));
    let doc = docs.next().unwrap_or_else(|| panic!("{name}: empty"));
    assert!(docs.next().is_none(), "{name}: one document per file");
    doc
}

/// Every `deploy/agones/*.yaml`, by file name.
fn manifests() -> BTreeMap<String, Value> {
    let dir = Path::new(DEPLOY).join("agones");
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.ends_with(".yaml") || name.ends_with(".yml") {
            out.insert(name.clone(), manifest(&name));
        }
    }
    out
}

/// Object schemas that list their properties and say nothing of others
/// (`additionalProperties`, `x-kubernetes-preserve-unknown-fields`) get
/// `additionalProperties: false`: the API server drops such fields, and
/// `kubectl` (strict field validation) refuses them. `nullable: true` (an
/// OpenAPI keyword) becomes a `null` type.
fn structural(schema: &mut Value) {
    match schema {
        Value::Object(map) => {
            if map.contains_key("properties")
                && !map.contains_key("additionalProperties")
                && !map.contains_key("x-kubernetes-preserve-unknown-fields")
            {
                map.insert("additionalProperties".into(), Value::Bool(false));
            }
            if map.get("nullable") == Some(&Value::Bool(true)) {
                if let Some(Value::String(t)) = map.get("type").cloned() {
                    map.insert("type".into(), json!([t, "null"]));
                }
            }
            for (key, value) in map.iter_mut() {
                // `properties` and `definitions` map names to schemas: walk
                // into the schemas, not the maps themselves.
                if key == "properties" || key == "definitions" || key == "patternProperties" {
                    if let Value::Object(named) = value {
                        named.values_mut().for_each(structural);
                    }
                } else if key != "enum" && key != "default" && key != "example" {
                    structural(value);
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(structural),
        _ => {}
    }
}

/// Agones' schema of `kind` (a CRD's `openAPIV3Schema`) as a validator of
/// whole manifests: the CRD leaves out `apiVersion`, `kind` and
/// `metadata`, which every object has; they are added here.
fn crd_validator(kind: &str, api_version: &str) -> Validator {
    let dir = agones_schemas();
    let path = dir.join(format!("{kind}.json"));
    assert!(
        path.is_file(),
        "{} is missing: Agones' CRD schemas belong in {} (how to make them: \
         deploy/agones/schema/README.md)",
        path.display(),
        dir.display()
    );
    let mut schema: Value = serde_json::from_str(&read(&path)).unwrap();
    let properties = schema["properties"]
        .as_object_mut()
        .unwrap_or_else(|| panic!("{}: no properties", path.display()));
    assert!(properties.contains_key("spec"), "{}", path.display());
    properties.insert(
        "apiVersion".into(),
        json!({"type": "string", "enum": [api_version]}),
    );
    properties.insert("kind".into(), json!({"type": "string", "enum": [kind]}));
    properties.insert("metadata".into(), object_meta());
    let required = schema
        .as_object_mut()
        .unwrap()
        .entry("required")
        .or_insert_with(|| json!([]));
    for field in ["apiVersion", "kind", "spec"] {
        if !required.as_array().unwrap().contains(&json!(field)) {
            required.as_array_mut().unwrap().push(json!(field));
        }
    }
    structural(&mut schema);
    jsonschema::draft4::new(&schema).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The `metadata` a manifest may give (Kubernetes' ObjectMeta, the fields
/// one writes).
fn object_meta() -> Value {
    let strings = json!({"type": "object", "additionalProperties": {"type": "string"}});
    json!({
        "type": "object",
        "properties": {
            "name": {"type": "string", "minLength": 1},
            "generateName": {"type": "string", "minLength": 1},
            "namespace": {"type": "string", "minLength": 1},
            "labels": strings,
            "annotations": strings,
        }
    })
}

/// Ours for GameServerAllocation (`deploy/agones/schema/`).
fn allocation_validator() -> Validator {
    let path = Path::new(DEPLOY).join("agones/schema/gameserverallocation.schema.json");
    let schema: Value = serde_json::from_str(&read(&path)).unwrap();
    jsonschema::draft4::new(&schema).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The kinds whose schemas are Agones' CRDs.
const CRD_KINDS: [(&str, &str); 3] = [
    ("agones.dev/v1", "GameServer"),
    ("agones.dev/v1", "Fleet"),
    ("autoscaling.agones.dev/v1", "FleetAutoscaler"),
];

/// A validator for every kind the manifests use, by kind (each schema
/// checks the apiVersion); Agones' kinds only when their schemas are
/// there.
struct Schemas(BTreeMap<&'static str, Validator>);

impl Schemas {
    fn load() -> Schemas {
        let mut map = BTreeMap::new();
        if agones_schemas().join("GameServer.json").is_file() {
            for (api_version, kind) in CRD_KINDS {
                map.insert(kind, crd_validator(kind, api_version));
            }
        } else {
            // Straight to stderr: the harness captures `eprintln!`.
            let notice = format!(
                "\n*** NOT CHECKED against Agones' schemas: {} does not hold them (they \
                 belong in the steering repository's shared/testdata/agones; see \
                 deploy/agones/schema/README.md). GameServer, Fleet and FleetAutoscaler \
                 are checked by the other tests only. ***\n\n",
                agones_schemas().display()
            );
            let _ = std::io::Write::write_all(&mut std::io::stderr(), notice.as_bytes());
        }
        map.insert("GameServerAllocation", allocation_validator());
        Schemas(map)
    }

    /// Whether `doc`'s kind can be checked here: ours, or Agones' with
    /// their schemas present.
    fn knows(&self, doc: &Value) -> bool {
        let kind = doc["kind"].as_str().unwrap_or_default();
        self.0.contains_key(kind) || !CRD_KINDS.iter().any(|(_, k)| *k == kind)
    }

    /// Every error of `doc` against its kind's schema, as `path: message`.
    fn errors(&self, doc: &Value) -> Vec<String> {
        let kind = doc["kind"].as_str().unwrap_or_default();
        let Some(validator) = self.0.get(kind) else {
            return vec![format!("/kind: no schema for kind {kind:?}")];
        };
        validator
            .iter_errors(doc)
            .map(|e| format!("{}: {e}", e.instance_path()))
            .collect()
    }
}

#[test]
fn every_manifest_is_valid_against_its_kinds_schema() {
    let schemas = Schemas::load();
    let all = manifests();
    assert_eq!(
        all.keys().map(String::as_str).collect::<Vec<_>>(),
        MANIFESTS,
        "deploy/agones/*.yaml (a new manifest: add it here and to docs/DEPLOY.md)"
    );
    for (name, doc) in all.iter().filter(|(_, d)| schemas.knows(d)) {
        let errors = schemas.errors(doc);
        assert!(errors.is_empty(), "{name}:\n{}", errors.join("\n"));
    }
}

/// Sets the value at a JSON pointer (whose parent exists) in a copy.
fn with(doc: &Value, pointer: &str, value: Value) -> Value {
    let mut doc = doc.clone();
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let parent = doc
        .pointer_mut(parent)
        .unwrap_or_else(|| panic!("{parent} not in the manifest"));
    match parent {
        Value::Object(map) => {
            map.insert(key.to_string(), value);
        }
        Value::Array(items) => items[key.parse::<usize>().unwrap()] = value,
        _ => panic!("{pointer}: parent is not a container"),
    }
    doc
}

/// Renames the key at a JSON pointer in a copy (a misspelling).
fn renamed(doc: &Value, pointer: &str, to: &str) -> Value {
    let mut doc = doc.clone();
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let map = doc.pointer_mut(parent).unwrap().as_object_mut().unwrap();
    let value = map
        .remove(key)
        .unwrap_or_else(|| panic!("{pointer} not in the manifest"));
    map.insert(to.to_string(), value);
    doc
}

/// Removes the key at a JSON pointer in a copy.
fn without(doc: &Value, pointer: &str) -> Value {
    let mut doc = doc.clone();
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let map = doc.pointer_mut(parent).unwrap().as_object_mut().unwrap();
    assert!(map.remove(key).is_some(), "{pointer} not in the manifest");
    doc
}

#[test]
fn broken_manifests_are_rejected_where_they_are_broken() {
    let schemas = Schemas::load();
    let gs = manifest("gameserver.yaml");
    let fleet = manifest("fleet.yaml");
    let scaler = manifest("fleetautoscaler.yaml");
    let any = manifest("allocation-any-room.yaml");
    let named = manifest("allocation-named-room.yaml");
    let port = "/spec/ports/0";
    let tpl = "/spec/template/spec";
    // (what, broken copy, where the error must be reported)
    let cases: Vec<(&str, Value, String)> = vec![
        (
            "unknown port policy",
            with(&gs, &format!("{port}/portPolicy"), json!("Sometimes")),
            format!("{port}/portPolicy"),
        ),
        (
            "port as a string",
            with(&gs, &format!("{port}/containerPort"), json!("4433")),
            format!("{port}/containerPort"),
        ),
        (
            "port out of range",
            with(&gs, &format!("{port}/containerPort"), json!(70000)),
            format!("{port}/containerPort"),
        ),
        (
            "QUIC over a protocol Agones does not have",
            with(&gs, &format!("{port}/protocol"), json!("QUIC")),
            format!("{port}/protocol"),
        ),
        (
            "a misspelt port key",
            renamed(&gs, &format!("{port}/containerPort"), "containerport"),
            port.to_string(),
        ),
        (
            "health period with a unit",
            with(&gs, "/spec/health/periodSeconds", json!("5s")),
            "/spec/health/periodSeconds".into(),
        ),
        (
            "negative Counter capacity",
            with(&gs, "/spec/counters/rooms/capacity", json!(-1)),
            "/spec/counters/rooms/capacity".into(),
        ),
        (
            "List capacity over Agones' 1000",
            with(&gs, "/spec/lists/rooms/capacity", json!(1001)),
            "/spec/lists/rooms/capacity".into(),
        ),
        (
            "a Counter as a number",
            with(&gs, "/spec/counters/rooms", json!(16)),
            "/spec/counters/rooms".into(),
        ),
        (
            "the container's args as one string",
            with(
                &gs,
                "/spec/template/spec/containers/0/args",
                json!("--max-rooms 16"),
            ),
            "/spec/template/spec/containers/0/args".into(),
        ),
        (
            "the emptyDir misspelt",
            renamed(&gs, "/spec/template/spec/volumes/0/emptyDir", "emptydir"),
            "/spec/template/spec/volumes/0".into(),
        ),
        (
            "apiVersion of another version",
            with(&gs, "/apiVersion", json!("agones.dev/v2")),
            "/apiVersion".into(),
        ),
        (
            "a kind Agones does not have",
            with(&gs, "/kind", json!("GameSever")),
            "/kind".into(),
        ),
        (
            "Fleet replicas as a word",
            with(&fleet, "/spec/replicas", json!("two")),
            "/spec/replicas".into(),
        ),
        (
            "unknown Fleet scheduling",
            with(&fleet, "/spec/scheduling", json!("Tight")),
            "/spec/scheduling".into(),
        ),
        (
            "unknown port policy in the Fleet's template",
            with(
                &fleet,
                &format!("{tpl}/ports/0/portPolicy"),
                json!("Sometimes"),
            ),
            format!("{tpl}/ports/0/portPolicy"),
        ),
        (
            "Fleet without a template",
            without(&fleet, "/spec/template"),
            "/spec".into(),
        ),
        (
            "unknown autoscaler policy",
            with(&scaler, "/spec/policy/type", json!("Rooms")),
            "/spec/policy/type".into(),
        ),
        (
            "Counter policy without maxCapacity",
            without(&scaler, "/spec/policy/counter/maxCapacity"),
            "/spec/policy/counter".into(),
        ),
        (
            "autoscaler sync every 0 s",
            with(&scaler, "/spec/sync/fixedInterval/seconds", json!(0)),
            "/spec/sync/fixedInterval/seconds".into(),
        ),
        (
            "allocation from a state Agones does not have",
            with(&any, "/spec/selectors/0/gameServerState", json!("Full")),
            "/spec/selectors/0/gameServerState".into(),
        ),
        (
            "minAvailable as a string",
            with(
                &any,
                "/spec/selectors/0/counters/rooms/minAvailable",
                json!("1"),
            ),
            "/spec/selectors/0/counters/rooms/minAvailable".into(),
        ),
        (
            "unknown priority order",
            with(&any, "/spec/priorities/0/order", json!("Fullest")),
            "/spec/priorities/0/order".into(),
        ),
        (
            "unknown allocation scheduling",
            with(&any, "/spec/scheduling", json!("Tight")),
            "/spec/scheduling".into(),
        ),
        (
            // Agones would drop it and allocate any server.
            "containsValue misspelt",
            renamed(
                &named,
                "/spec/selectors/0/lists/rooms/containsValue",
                "containsValues",
            ),
            "/spec/selectors/0/lists/rooms".into(),
        ),
        (
            "a Counter action without an amount",
            with(
                &any,
                "/spec/counters",
                json!({"rooms": {"action": "Increment"}}),
            ),
            "/spec/counters/rooms".into(),
        ),
    ];
    let mut checked = 0;
    for (what, doc, at) in cases {
        if !schemas.knows(&doc) {
            continue;
        }
        checked += 1;
        let errors = schemas.errors(&doc);
        assert!(
            !errors.is_empty(),
            "{what}: accepted\n{}",
            serde_json::to_string_pretty(&doc).unwrap()
        );
        assert!(
            errors.iter().all(|e| e.starts_with(&format!("{at}:"))),
            "{what}: expected errors at {at}, got:\n{}",
            errors.join("\n")
        );
    }
    assert!(checked > 0, "no broken manifest checked");
}

#[test]
fn the_fleet_runs_the_gameserver_spec() {
    let gs = manifest("gameserver.yaml");
    let fleet = manifest("fleet.yaml");
    assert_eq!(
        fleet["spec"]["template"]["spec"], gs["spec"],
        "fleet.yaml's spec.template.spec and gameserver.yaml's spec differ"
    );
}

/// The image as deploy/Dockerfile makes it.
struct Image {
    /// `EXPOSE PORT/udp`.
    udp_port: u16,
    /// `ENTRYPOINT [...]`.
    entrypoint: Vec<String>,
    /// `USER UID[:GID]`'s UID.
    uid: u64,
    volumes: Vec<String>,
    /// Every `RUN`, continuation lines joined.
    runs: Vec<String>,
}

fn image() -> Image {
    let text = read(&Path::new(DEPLOY).join("Dockerfile"));
    let mut instructions = Vec::new();
    let mut current = String::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('#') || (line.is_empty() && current.is_empty()) {
            continue;
        }
        match line.strip_suffix('\\') {
            Some(part) => current.push_str(part),
            None => {
                current.push_str(line);
                instructions.push(std::mem::take(&mut current));
            }
        }
    }
    let args = |name: &str| {
        instructions
            .iter()
            .filter_map(|i| {
                let (word, rest) = i.split_once(char::is_whitespace)?;
                word.eq_ignore_ascii_case(name)
                    .then(|| rest.trim().to_string())
            })
            .collect::<Vec<_>>()
    };
    let [expose] = &args("EXPOSE")[..] else {
        panic!("one EXPOSE in deploy/Dockerfile");
    };
    let udp_port = expose
        .strip_suffix("/udp")
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("EXPOSE {expose}: one PORT/udp"));
    let [entrypoint] = &args("ENTRYPOINT")[..] else {
        panic!("one ENTRYPOINT in deploy/Dockerfile");
    };
    let entrypoint: Vec<String> = serde_json::from_str(entrypoint)
        .unwrap_or_else(|e| panic!("ENTRYPOINT {entrypoint}: not the exec form ({e})"));
    let users = args("USER");
    let user = users.last().expect("a USER in deploy/Dockerfile");
    let uid = user
        .split(':')
        .next()
        .unwrap()
        .parse()
        .unwrap_or_else(|_| panic!("USER {user}: a numeric UID (runAsNonRoot checks it)"));
    Image {
        udp_port,
        entrypoint,
        uid,
        volumes: args("VOLUME"),
        runs: args("RUN"),
    }
}

/// `n` of a Counter or List in a GameServer spec.
fn capacity(spec: &Value, what: &str, name: &str) -> u64 {
    spec[what][name]["capacity"]
        .as_u64()
        .unwrap_or_else(|| panic!("spec.{what}.{name}.capacity"))
}

#[test]
fn the_gameserver_declares_what_the_server_reports_on_the_port_it_listens_on() {
    let image = image();
    let spec = manifest("gameserver.yaml")["spec"].clone();

    // The image: the SDK compiled in and turned on.
    assert!(
        image
            .runs
            .iter()
            .any(|r| r.contains("cargo build") && r.contains("--features agones")),
        "the image builds ledge-server with --features agones: {:?}",
        image.runs
    );
    assert_eq!(image.entrypoint[0], "ledge-server");
    assert!(image.entrypoint.contains(&"--agones".to_string()));

    // The game container, and the command it runs: the image's entrypoint
    // and the GameServer's args.
    let container_name = spec["container"].as_str().expect("spec.container");
    let containers = spec["template"]["spec"]["containers"].as_array().unwrap();
    let container = containers
        .iter()
        .find(|c| c["name"] == container_name)
        .unwrap_or_else(|| panic!("no container {container_name}"));
    assert!(
        container.get("command").is_none(),
        "the image's entrypoint runs"
    );
    let extra: Vec<String> = container["args"]
        .as_array()
        .map(|a| a.iter().map(|v| v.as_str().unwrap().to_string()).collect())
        .unwrap_or_default();
    let command: Vec<String> = image.entrypoint.iter().chain(&extra).cloned().collect();

    // The server's own command line reads it, the `--agones*` flags too.
    let config = Cli::try_parse_from(&command)
        .unwrap_or_else(|e| panic!("{command:?}: {e}"))
        .resolve()
        .unwrap_or_else(|e| panic!("{command:?}: {e}"));
    let fleet = config
        .agones
        .expect("the image runs the server with --agones");

    // It runs no more threads than the cores the container asks for (the
    // runtime's default is one per core of the node).
    let cpu = container["resources"]["requests"]["cpu"]
        .as_str()
        .expect("a CPU request");
    let millicores: u64 = match cpu.strip_suffix('m') {
        Some(m) => m.parse().unwrap(),
        None => cpu.parse::<u64>().unwrap() * 1000,
    };
    let threads = config.threads.expect("--threads set") as u64;
    assert!(
        threads <= millicores.div_ceil(1000),
        "--threads {threads} for a CPU request of {cpu}"
    );

    // It listens on the port the image exposes and the GameServer opens.
    assert_eq!(config.bind.port(), image.udp_port, "--bind and EXPOSE");
    let ports = spec["ports"].as_array().expect("spec.ports");
    assert_eq!(ports.len(), 1, "{ports:?}");
    assert_eq!(ports[0]["containerPort"], json!(image.udp_port));
    assert_eq!(ports[0]["protocol"], "UDP", "QUIC runs on UDP");
    assert_eq!(ports[0]["portPolicy"], "Dynamic");

    // What it reports through the SDK is declared (the SDK's Counter and
    // List calls fail otherwise), with the capacities its flags give.
    for counter in COUNTERS {
        assert!(
            spec["counters"].get(counter).is_some(),
            "spec.counters.{counter}: the server reports it"
        );
    }
    for list in LISTS {
        assert!(
            spec["lists"].get(list).is_some(),
            "spec.lists.{list}: the server reports it"
        );
    }
    let max_rooms = u64::from(config.max_rooms);
    let max_players = config.max_players as u64;
    assert_eq!(capacity(&spec, "counters", "rooms"), max_rooms);
    assert_eq!(capacity(&spec, "lists", "rooms"), max_rooms);
    assert_eq!(
        capacity(&spec, "counters", "players"),
        max_rooms * max_players
    );
    for counter in COUNTERS {
        assert_eq!(spec["counters"][counter]["count"], json!(0), "{counter}");
    }

    // Health: the pings (every --agones-health-every seconds, default 2)
    // fit at least twice in a period.
    let every = fleet.health_every.as_secs_f64();
    let period = spec["health"]["periodSeconds"].as_u64().unwrap();
    assert!(
        period as f64 >= 2.0 * every,
        "health.periodSeconds {period}, pings every {every} s"
    );

    // The certificate directory is the image's volume, an emptyDir in the
    // pod (one certificate per GameServer), written as the image's user.
    assert!(image
        .volumes
        .contains(&config.cert_dir.display().to_string()));
    let mounts = container["volumeMounts"].as_array().unwrap();
    let mount = mounts
        .iter()
        .find(|m| m["mountPath"] == json!(config.cert_dir))
        .unwrap_or_else(|| panic!("nothing mounted at {}", config.cert_dir.display()));
    let volumes = spec["template"]["spec"]["volumes"].as_array().unwrap();
    let volume = volumes.iter().find(|v| v["name"] == mount["name"]).unwrap();
    assert!(volume.get("emptyDir").is_some(), "{volume}");
    let pod_security = &spec["template"]["spec"]["securityContext"];
    assert_eq!(pod_security["runAsUser"], json!(image.uid));
    assert_eq!(pod_security["runAsNonRoot"], json!(true));
}

#[test]
fn allocations_and_the_autoscaler_use_the_fleet_and_what_it_reports() {
    let fleet = manifest("fleet.yaml");
    let fleet_name = fleet["metadata"]["name"].as_str().unwrap();
    let spec = &fleet["spec"]["template"]["spec"];
    let declared = |what: &str, key: &str| spec[what].get(key).is_some();

    for name in ["allocation-any-room.yaml", "allocation-named-room.yaml"] {
        let gsa = manifest(name);
        let selectors = gsa["spec"]["selectors"].as_array().unwrap();
        assert!(!selectors.is_empty(), "{name}");
        for (i, s) in selectors.iter().enumerate() {
            assert_eq!(
                s["matchLabels"]["agones.dev/fleet"], fleet_name,
                "{name}: selector {i} picks from the Fleet"
            );
            for (what, map) in [("counters", &s["counters"]), ("lists", &s["lists"])] {
                for key in map.as_object().into_iter().flat_map(|m| m.keys()) {
                    assert!(declared(what, key), "{name}: selector {i}: {what}.{key}");
                }
            }
        }
        for p in gsa["spec"]["priorities"].as_array().into_iter().flatten() {
            let what = match p["type"].as_str() {
                Some("Counter") => "counters",
                _ => "lists",
            };
            assert!(declared(what, p["key"].as_str().unwrap()), "{name}: {p}");
        }
        // The server owns its Counters and List: an allocation that changed
        // them would be overwritten, or counted twice.
        for field in ["counters", "lists"] {
            assert!(gsa["spec"].get(field).is_none(), "{name}: spec.{field}");
        }
    }

    // Any room: an Allocated server with a free room first, then a Ready one.
    let any = manifest("allocation-any-room.yaml");
    let states: Vec<&str> = any["spec"]["selectors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["gameServerState"].as_str().unwrap_or("Ready"))
        .collect();
    assert_eq!(states, ["Allocated", "Ready"]);
    for s in any["spec"]["selectors"].as_array().unwrap() {
        assert_eq!(s["counters"]["rooms"]["minAvailable"], json!(1), "{s}");
    }
    // A named room: every selector looks for the same name, a valid one.
    let named = manifest("allocation-named-room.yaml");
    let names: Vec<&Value> = named["spec"]["selectors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| &s["lists"]["rooms"]["containsValue"])
        .collect();
    let room = names[0].as_str().expect("lists.rooms.containsValue");
    assert!(names.iter().all(|n| *n == names[0]), "{names:?}");
    // Checked as the server checks a client's room name.
    check_text("room name", room, 1, MAX_ID_LEN)
        .unwrap_or_else(|e| panic!("{room:?}: not a room name: {e}"));

    // The autoscaler scales this Fleet on a declared Counter, within bounds
    // that hold a buffer.
    let scaler = manifest("fleetautoscaler.yaml");
    assert_eq!(scaler["spec"]["fleetName"], fleet_name);
    assert_eq!(scaler["spec"]["policy"]["type"], "Counter");
    let counter = &scaler["spec"]["policy"]["counter"];
    assert!(declared("counters", counter["key"].as_str().unwrap()));
    let buffer = counter["bufferSize"]
        .as_u64()
        .expect("bufferSize: a number of rooms");
    let (min, max) = (
        counter["minCapacity"].as_u64().unwrap(),
        counter["maxCapacity"].as_u64().unwrap(),
    );
    assert!(buffer > 0 && buffer <= min && min <= max, "{counter}");
    // Whole servers: capacities in steps of one server's rooms.
    let per_server = capacity(spec, "counters", counter["key"].as_str().unwrap());
    assert!(
        min % per_server == 0 && max % per_server == 0,
        "{counter}, {per_server} per server"
    );
}
