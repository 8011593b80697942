#!/usr/bin/env python3
"""Writes the largest Tiled map the level limits allow (2048 x 2048 CSV cells,
MAX_LEVEL_CELLS), 10 % solid tiles plus a floor, for the level-loading figures
in docs/PERFORMANCE.md:

    python3 scripts/big-level.py /tmp/big.tmx
    /usr/bin/time -f "%e s, %M KB max RSS" ./target/release/ledge-level check /tmp/big.tmx
"""
import random
import sys

W = H = 2048
random.seed(1)
rows = [
    ",".join("1" if (y > H - 8 or random.random() < 0.1) else "0" for _ in range(W))
    for y in range(H)
]
data = ",\n".join(rows)
with open(sys.argv[1] if len(sys.argv) > 1 else "big.tmx", "w") as f:
    f.write(f"""<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="{W}" height="{H}" tilewidth="16" tileheight="16" infinite="0">
 <tileset firstgid="1" name="t" tilewidth="16" tileheight="16" tilecount="1" columns="1">
  <image source="t.png" width="16" height="16"/>
  <tile id="0"><properties><property name="solid" type="bool" value="true"/></properties></tile>
 </tileset>
 <layer id="1" name="Ground" width="{W}" height="{H}"><data encoding="csv">{data}</data></layer>
 <objectgroup id="2" name="o"><object id="1" name="spawn" x="16" y="16" width="16" height="16"/></objectgroup>
</map>""")
