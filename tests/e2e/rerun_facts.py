"""What Rerun itself reads in an .rrd: the facts `analyze view`'s acceptance test asserts on.

Run with the Python of a venv that has rerun-sdk 0.41 (`ELBOW_RERUN_PYTHON`). Reads the file
with the SDK's own reader (`rerun.chunk.RrdReader`, the code the viewer loads with), migrating
chunks to the SDK's version, and prints one JSON object:

- `stores`: every store, `{kind, application_id, recording_id}`;
- `views`: the blueprint's views, `{class, name, origin, query}` (from `ViewBlueprint` and
  `ViewContents` of the blueprint store);
- `containers`: the blueprint's containers, `{kind, contents}` (`ContainerKind` code,
  `container/...` / `view/...` entries);
- `entities`: per entity path of the recording, its component columns (`Archetype:field`);
- `timelines`: per index column of the recording, its Arrow type;
- `series_names`: per entity with `SeriesLines:names`, the names;
- `rows`: per entity with `Scalars:scalars`, how many rows.
"""

import json
import sys
import warnings

from rerun.chunk import RrdReader


def first(batch, column):
    if column not in batch.schema.names:
        return None
    values = batch.column(column).to_pylist()
    return values[0] if values else None


def main(path):
    warnings.simplefilter("ignore")
    reader = RrdReader(path)
    facts = {"stores": [], "views": [], "containers": [], "entities": {}, "timelines": {}, "series_names": {}, "rows": {}}
    for store in reader.recordings() + reader.blueprints():
        facts["stores"].append({"kind": store.kind, "application_id": store.application_id, "recording_id": store.recording_id})
    views = {}
    for store in reader.blueprints():
        for chunk in reader.stream(store=store):
            b = chunk.to_record_batch()
            path = chunk.entity_path
            if "ViewBlueprint:class_identifier" in b.schema.names:
                v = views.setdefault(path, {})
                v["class"] = first(b, "ViewBlueprint:class_identifier")[0]
                v["name"] = (first(b, "ViewBlueprint:display_name") or [""])[0]
                v["origin"] = (first(b, "ViewBlueprint:space_origin") or [""])[0]
            if "ViewContents:query" in b.schema.names:
                views.setdefault(path.rsplit("/", 1)[0], {})["query"] = first(b, "ViewContents:query")
            if "ContainerBlueprint:container_kind" in b.schema.names:
                facts["containers"].append(
                    {"kind": first(b, "ContainerBlueprint:container_kind")[0], "contents": first(b, "ContainerBlueprint:contents") or []}
                )
    facts["views"] = [{"class": v.get("class"), "name": v.get("name"), "origin": v.get("origin"), "query": v.get("query") or []} for v in views.values() if "class" in v]
    for store in reader.recordings():
        for chunk in reader.stream(store=store):
            b = chunk.to_record_batch()
            path = chunk.entity_path
            cols = facts["entities"].setdefault(path, [])
            for field in b.schema:
                kind = (field.metadata or {}).get(b"rerun:kind", b"").decode()
                if kind == "index":
                    facts["timelines"][field.name] = str(field.type)
                elif kind == "data" and field.name not in cols:
                    cols.append(field.name)
            if "SeriesLines:names" in b.schema.names:
                facts["series_names"][path] = first(b, "SeriesLines:names")
            if "Scalars:scalars" in b.schema.names:
                facts["rows"][path] = facts["rows"].get(path, 0) + b.num_rows
    json.dump(facts, sys.stdout, indent=1, sort_keys=True)


if __name__ == "__main__":
    main(sys.argv[1])
