#!/usr/bin/env python3
"""Writes ledge's default level: ledge.png, ledge.ogmo (OGMO Editor 3 project)
and default.json (the level), next to this script.

The JSON files are the source of truth once written (open them in OGMO
Editor 3.3 to edit); this script records how they were made and can
regenerate them. The tileset is the echo-slopes one (MIT, Austin East, see
README.md) read from the test data, with spikes drawn in the blank slot 13.

    python3 levels/default/generate.py
"""
import base64
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ECHO = os.path.join(HERE, "../../../shared/testdata/levels/echo-slopes/project.ogmo")
T = 16
W, H = 100, 30

# Tile ids of the tileset (see shared/src/level/mapping.rs, LEDGE_TILESET).
EMPTY, SOLID, R45, L45, R22LO, R22HI, L22HI, L22LO, ONE_WAY, SPIKES = -1, 1, 2, 3, 4, 5, 6, 7, 12, 13


# ---------------------------------------------------------------- tileset
def png_decode(data):
    pos, chunks, idat = 8, {}, b""
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        pos += 12 + n
        if kind == b"IDAT":
            idat += body
        else:
            chunks[kind] = body
    w, h, depth, ctype, _, _, inter = struct.unpack(">IIBBBBB", chunks[b"IHDR"])
    assert (depth, ctype, inter) == (8, 3, 0), "expects an 8-bit paletted PNG"
    raw, rows, prev, i = zlib.decompress(idat), [], bytearray(w), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1 : i + 1 + w])
        i += 1 + w
        for x in range(w):
            a = line[x - 1] if x else 0
            b, c = prev[x], (prev[x - 1] if x else 0)
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, rows, chunks[b"PLTE"], chunks.get(b"tRNS", b"")


def png_encode(w, h, rows, plte, trns):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    raw = b"".join(b"\0" + bytes(r) for r in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 3, 0, 0, 0))
    out += chunk(b"PLTE", plte)
    if trns:
        out += chunk(b"tRNS", trns)
    return out + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def tileset_png():
    echo = json.load(open(ECHO))
    uri = echo["tilesets"][0]["image"]
    w, h, rows, plte, trns = png_decode(base64.b64decode(uri.split(",", 1)[1]))
    # Spikes in slot 13 (column 0 of row 1): three teeth, outline 2, fill 3.
    x0, y0 = (SPIKES % 13) * T, (SPIKES // 13) * T
    for y in range(T):
        for x in range(T):
            rows[y0 + y][x0 + x] = 0
    for tooth in range(3):
        left = tooth * 5 + 1
        for y in range(6, T):
            half = (y - 6) * 5 // 20
            for x in range(left + 2 - half, left + 3 + half):
                if 0 <= x < T:
                    edge = x in (left + 2 - half, left + 2 + half) or y == T - 1
                    rows[y0 + y][x0 + x] = 2 if edge else 3
    return png_encode(w, h, rows, plte, trns)


# ---------------------------------------------------------------- tiles
grid = [[EMPTY] * W for _ in range(H)]


def fill(c0, r0, c1, r1, tile):
    """Inclusive rectangle of tiles."""
    for r in range(r0, r1 + 1):
        for c in range(c0, c1 + 1):
            grid[r][c] = tile


def column_down(c, r, tile):
    """`tile` at (c, r), solid below it to the bottom."""
    grid[r][c] = tile
    fill(c, r + 1, c, H - 1, SOLID)


fill(0, 0, W - 1, 0, SOLID)  # ceiling
fill(0, 0, 0, H - 1, SOLID)  # walls
fill(W - 1, 0, W - 1, H - 1, SOLID)
fill(0, 26, W - 1, H - 1, SOLID)  # ground, top at row 26
fill(4, 10, 20, 10, ONE_WAY)  # bonus shelf, reached by the elevator
# 45 degree peak (two tiles high)
grid[25][12], grid[25][13], grid[25][14], grid[25][15] = R45, SOLID, SOLID, L45
grid[24][13], grid[24][14] = R45, L45
# 22.5 degree hill with the first checkpoint on top
grid[25][19], grid[25][20] = R22LO, R22HI
fill(21, 25, 23, 25, SOLID)
grid[25][24], grid[25][25] = L22HI, L22LO
fill(29, 25, 31, 25, SPIKES)  # spike strip
fill(36, 26, 43, 26, EMPTY)  # walker trench, floor at row 27
fill(36, 24, 38, 24, ONE_WAY)  # one-way steps over it
fill(40, 22, 42, 22, ONE_WAY)
fill(44, 20, 52, H - 1, SOLID)  # high plateau, top at row 20
column_down(53, 20, L22HI)  # two 22.5 degree ramps and a 45 degree step down
column_down(54, 20, L22LO)
column_down(55, 21, L22HI)
column_down(56, 21, L22LO)
column_down(57, 22, L45)
fill(58, 23, 64, H - 1, SOLID)  # springboard yard, top at row 23
fill(65, 17, 72, H - 1, SOLID)  # ledge, top at row 17
for i in range(9):  # long 45 degree slope down to the ground
    column_down(73 + i, 17 + i, L45)
fill(86, 25, 87, 25, SPIKES)  # last spikes

# ---------------------------------------------------------------- entities
_ids = iter(range(1000))


def ent(name, x, y, **kw):
    e = {"name": name, "id": next(_ids), "_eid": EIDS[name], "x": x, "y": y}
    e.update(kw)
    return e


EIDS = {
    "player": "10000001",
    "block": "10000002",
    "platform": "10000003",
    "walker": "10000004",
    "springboard": "10000005",
    "coin": "10000006",
    "checkpoint": "10000007",
    "goal": "10000008",
    "spikes": "10000009",
    "waypoint": "10000010",
    "polygon": "10000011",
}


def platform(c, r, nodes, speed=1, one_way=False, loop=False):
    return ent(
        "platform",
        c * T,
        r * T,
        width=48,
        height=16,
        originX=0,
        originY=0,
        nodes=[{"x": nc * T, "y": nr * T} for nc, nr in nodes],
        values={"speed": speed, "one_way": one_way, "loop": loop},
    )


def polygon(points):
    """A convex polygon solid: its position is the first vertex, its nodes the
    others (pixels)."""
    (x, y), rest = points[0], points[1:]
    return ent("polygon", x, y, nodes=[{"x": nx, "y": ny} for nx, ny in rest])


def coin(c, r):
    return ent("coin", c * T + 2, r * T + 2)


entities = [
    # The spawn's origin is its bottom-centre (x, y = the feet).
    ent("player", 5 * T + 8, 26 * T),
    ent("block", 9 * T, 25 * T),
    platform(1, 25, [(1, 10)]),  # elevator (up/down) to the bonus shelf
    platform(27, 18, [(34, 18)]),  # sideways, over the spike strip
    platform(58, 12, [(70, 12)], speed=1.5, one_way=True),  # one-way, sideways
    platform(84, 19, [(92, 11), (92, 19)], loop=True),  # diagonal, looping
    ent("walker", 39 * T, 26 * T, values={"speed": 0.5}),  # in the trench
    ent("walker", 15 * T, 9 * T, values={"speed": 0.75}),  # on the shelf
    ent("springboard", 62 * T, 23 * T - 8, values={"strength": 10}),
    ent("checkpoint", 22 * T, 23 * T),
    ent("checkpoint", 68 * T, 15 * T),
    ent("goal", 96 * T, 24 * T),
    ent("spikes", 19 * T, 9 * T + 8),
] + [
    coin(c, r)
    for c, r in [(8, 9), (11, 9), (13, 22), (21, 22), (30, 16), (37, 22), (41, 20),
                 (48, 18), (64, 10), (76, 19), (79, 22), (92, 9), (93, 24)]
] + [
    # A 1:4 wedge on the bonus shelf between two coins, off the bot route
    # (last, so the other entities keep their ids).
    polygon([(9 * T, 10 * T), (11 * T, 10 * T - 8), (11 * T, 10 * T)]),
]


def wp(c, row, action="walk"):
    """Waypoint: foot at x = c tiles, on the surface at the top of `row`."""
    return ent("waypoint", int(c * T), row * T, values={"action": action})


route = [
    wp(5.5, 26),  # spawn
    wp(8, 26),
    wp(11, 26, "jump"),  # over the crate
    wp(16.5, 26),  # over the 45 degree peak
    wp(22.5, 25),  # up the 22.5 degree hill: first checkpoint
    wp(27.5, 26),  # down the other side
    wp(33.5, 26, "jump"),  # over the spike strip
    wp(34.5, 26),
    wp(37, 24, "jump"),  # one-way steps over the walker trench
    wp(41, 22, "jump"),
    wp(46, 20, "jump"),  # onto the high plateau
    wp(60, 23),  # down the ramps into the yard
    wp(67, 17, "spring"),  # springboard up to the ledge
    wp(68.5, 17),  # second checkpoint
    wp(83, 26),  # down the long 45 degree slope
    wp(84.5, 26),
    wp(89.5, 26, "jump"),  # over the last spikes
    wp(96.5, 26),  # the goal
]


# ---------------------------------------------------------------- files
def entity_def(name, w, h, color, origin=(0, 0), nodes=False, values=(), resize=False):
    return {
        "exportID": EIDS[name],
        "name": name,
        "limit": 1 if name == "player" else -1,
        "size": {"x": w, "y": h},
        "origin": {"x": origin[0], "y": origin[1]},
        "originAnchored": True,
        "shape": {
            "label": "Rectangle",
            "points": [{"x": -1, "y": -1}, {"x": 1, "y": -1}, {"x": -1, "y": 1},
                       {"x": 1, "y": -1}, {"x": -1, "y": 1}, {"x": 1, "y": 1}],
        },
        "color": color,
        "tileX": False,
        "tileY": False,
        "tileSize": {"x": 16, "y": 16},
        "resizeableX": resize,
        "resizeableY": resize,
        "rotatable": False,
        "rotationDegrees": 360,
        "canFlipX": False,
        "canFlipY": False,
        "canSetColor": False,
        "hasNodes": nodes,
        "nodeLimit": 0,
        "nodeDisplay": 0,
        "nodeGhost": True,
        "tags": [],
        "values": list(values),
    }


def polygon_def():
    """Polygon solids: the entity's position and its nodes are the vertices,
    drawn as a closed outline (node display 1, "path loop")."""
    d = entity_def("polygon", 4, 4, "#a4b0beff", origin=(2, 2), nodes=True)
    d["nodeLimit"] = 7
    d["nodeDisplay"] = 1
    return d


def fval(name, default):
    return {"name": name, "definition": "Float", "display": 0, "defaults": default,
            "bounded": True, "min": 0.0, "max": 64.0, "decimals": 2}


def bval(name):
    return {"name": name, "definition": "Boolean", "display": 0, "defaults": False}


png = tileset_png()
open(os.path.join(HERE, "ledge.png"), "wb").write(png)
project = {
    "name": "ledge",
    "ogmoVersion": "3.3.0",
    "levelPaths": ["."],
    "backgroundColor": "#282c34ff",
    "gridColor": "#3c4049cc",
    "anglesRadians": True,
    "directoryDepth": 5,
    "layerGridDefaultSize": {"x": 16, "y": 16},
    "levelDefaultSize": {"x": W * T, "y": H * T},
    "levelMinSize": {"x": 128, "y": 128},
    "levelMaxSize": {"x": 4096 * 16, "y": 4096 * 16},
    "levelValues": [],
    "defaultExportMode": ".json",
    "compactExport": False,
    "externalScript": "",
    "playCommand": "",
    "entityTags": [],
    "layers": [
        {"definition": "tile", "name": "tiles", "gridSize": {"x": 16, "y": 16},
         "exportID": "20000001", "exportMode": 0, "arrayMode": 1, "defaultTileset": "ledge"},
        {"definition": "entity", "name": "entities", "gridSize": {"x": 8, "y": 8},
         "exportID": "20000002", "requiredTags": [], "excludedTags": []},
        {"definition": "entity", "name": "route", "gridSize": {"x": 8, "y": 8},
         "exportID": "20000003", "requiredTags": [], "excludedTags": []},
    ],
    "entities": [
        entity_def("player", 16, 16, "#2e86deff", origin=(8, 16)),
        entity_def("block", 16, 16, "#8d6e63ff", resize=True),
        entity_def("platform", 48, 16, "#10ac84ff", nodes=True, resize=True,
                   values=[fval("speed", 1.0), bval("one_way"), bval("loop")]),
        entity_def("walker", 16, 16, "#ee5253ff", values=[fval("speed", 0.5)]),
        entity_def("springboard", 16, 8, "#ff9f43ff", values=[fval("strength", 10.0)]),
        entity_def("coin", 12, 12, "#feca57ff"),
        entity_def("checkpoint", 16, 32, "#48dbfbff"),
        entity_def("goal", 16, 32, "#1dd1a1ff"),
        entity_def("spikes", 16, 8, "#c8d6e5ff", resize=True),
        polygon_def(),
        entity_def("waypoint", 16, 16, "#ffffff66", origin=(8, 16),
                   values=[{"name": "action", "definition": "Enum", "display": 0,
                            "choices": ["walk", "jump", "spring"], "defaults": 0}]),
    ],
    "tilesets": [
        {"label": "ledge", "path": "ledge.png",
         "image": "data:image/png;base64," + base64.b64encode(png).decode(),
         "tileWidth": 16, "tileHeight": 16, "tileSeparationX": 0, "tileSeparationY": 0,
         "tileMarginX": 0, "tileMarginY": 0},
    ],
}
with open(os.path.join(HERE, "ledge.ogmo"), "w") as f:
    json.dump(project, f, indent=2)
    f.write("\n")


def layer(name, eid, **kw):
    d = {"name": name, "_eid": eid, "offsetX": 0, "offsetY": 0,
         "gridCellWidth": T if name == "tiles" else 8, "gridCellHeight": T if name == "tiles" else 8,
         "gridCellsX": W if name == "tiles" else W * 2, "gridCellsY": H if name == "tiles" else H * 2}
    d.update(kw)
    return d


level = {
    "ogmoVersion": "3.3.0",
    "width": W * T,
    "height": H * T,
    "offsetX": 0,
    "offsetY": 0,
    "layers": [
        layer("tiles", "20000001", tileset="ledge", data2D="@ROWS@", exportMode=0, arrayMode=1),
        layer("entities", "20000002", entities=entities),
        layer("route", "20000003", entities=route),
    ],
}
text = json.dumps(level, indent=2)
rows = ",\n".join("        " + json.dumps(r, separators=(",", ":")) for r in grid)
text = text.replace('"@ROWS@"', "[\n" + rows + "\n      ]")
with open(os.path.join(HERE, "default.json"), "w") as f:
    f.write(text + "\n")

ch = {EMPTY: ".", SOLID: "#", R45: "/", L45: "\\", R22LO: "a", R22HI: "b", L22HI: "c",
      L22LO: "d", ONE_WAY: "=", SPIKES: "^"}
for r in grid:
    print("".join(ch[t] for t in r))
