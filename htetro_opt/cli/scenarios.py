"""``htetro-opt scenarios``: the bundled scenarios and labelled tilesets."""

from __future__ import annotations

from htetro_opt.cli._common import add_outputs

__all__ = ["add_parser", "run"]


def add_parser(sub) -> None:
    p = sub.add_parser("scenarios", help="list the bundled scenarios")
    add_outputs(p)


def run(args) -> dict:
    from htetro_opt.scenarios import Scenario, list_scenarios, list_tilesets, load_scenario, load_tileset, tileset_path

    rows = []
    for name in list_scenarios():
        sc = load_scenario(name)
        if isinstance(sc, Scenario):
            rows.append({"name": name, "size": [sc.workspace.width, sc.workspace.height],
                         "roadmap": len(sc.roadmap), "moving": len(sc.workspace.moving), "source": sc.source})
        else:
            rows.append({"name": name, "size": [sc.width, sc.height], "roadmap": 0, "moving": 0, "source": sc.source})
    tilesets = []
    for name in list_tilesets():
        ts = load_tileset(tileset_path(name))
        tilesets.append({"name": name, "size": [ts.width, ts.height], "tiles": len(ts),
                         "source": "Le et al., Electronics 2018: the paper's labelled tileset"})
    if not args.json:
        width = max((len(r["name"]) for r in rows + tilesets), default=4)
        for r in rows:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['source']}")
        if tilesets:
            print("\nlabelled tilesets (for 'sequence'):")
        for r in tilesets:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['tiles']} tiles, {r['source']}")
    return {"scenarios": rows, "tilesets": tilesets}
