// ledge's glue between the browser and the client's wasm build: a
// miniquad plugin (miniquad's gl.js loads the wasm and calls
// `register_plugin` with its imports) giving the game the page's clock,
// the address's parameters, and a place to publish its state.
//
// The wasm checks the glue's version through `ledge_crate_version`
// (miniquad's loader logs a mismatch): keep GLUE_VERSION equal to
// `GLUE_VERSION` in client/src/bin/ledge-client/web.rs.
"use strict";

(function () {
    const GLUE_VERSION = 1;
    const decoder = new TextDecoder("utf-8");
    const encoder = new TextEncoder();

    // `wasm_memory` is gl.js's global, set once the module is instantiated.
    function bytes(ptr, len) {
        return new Uint8Array(wasm_memory.buffer, ptr, len);
    }

    miniquad_add_plugin({
        name: "ledge",
        version: GLUE_VERSION,
        register_plugin: function (importObject) {
            const env = importObject.env;
            // Milliseconds since the page loaded, monotonic.
            env.ledge_now_ms = function () {
                return performance.now();
            };
            // The address's parameter `name`, decoded, as UTF-8 into
            // `out` (at most `cap` bytes); its length, or -1 if absent.
            env.ledge_page_param = function (namePtr, nameLen, out, cap) {
                const name = decoder.decode(bytes(namePtr, nameLen));
                const value = new URLSearchParams(window.location.search).get(name);
                if (value === null) {
                    return -1;
                }
                const encoded = encoder.encode(value);
                const n = Math.min(encoded.length, cap);
                bytes(out, n).set(encoded.subarray(0, n));
                return n;
            };
            // The game's state (JSON) as `window.ledgeState`.
            env.ledge_report = function (ptr, len) {
                try {
                    window.ledgeState = JSON.parse(decoder.decode(bytes(ptr, len)));
                } catch (e) {
                    console.error("ledge: bad state report: " + e);
                }
            };
        },
    });
})();
