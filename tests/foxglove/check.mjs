// Checks recordings of one scene and their Foxglove layout with Foxglove's own libraries:
//
//   node check.mjs LAYOUT.json REC.mcap [REC.mcap ...]
//
// (a) the layout validates against layout.schema.json (derived from the open-source Foxglove
//     Studio / Lichtblick types; the file says which) with ajv, and its mosaic tree names exactly
//     the panels it configures;
// (b) every topic the layout names (3D topics, plot and band paths, Table panels) exists in every
//     recording with at least one message, and every plot path resolves, in the protobuf schema
//     embedded in the recording (FileDescriptorSet, decoded with protobufjs as Foxglove does:
//     packages/mcap-support/src/parseProtobufSchema.ts), to a numeric field (a State
//     Transitions band: a number or a string), and gives a finite number (a band: a number or a
//     non-empty string) in at least one message of the recordings;
// (c) every /scene and /contact_markers message decodes (protobufjs on the embedded descriptor,
//     whose foxglove.* message fields are compared with @foxglove/schemas' definitions by the
//     .proto text @foxglove/schemas generates), with the entities (each touching contact's two
//     in every message, a separated one's deleted at the sample it separates and absent while
//     it stays separated), the mode colours, the
//     arrow lengths max(|F| x scale, shortest) (1e-9 m) at the one scale of /scene's scale bar
//     (the same in every recording given), the arrows' normal component f_n (1e-9 N), each
//     arrow starting on the plane at the contact point's projection, every nonzero force's
//     arrow at least 20 mm outside its marker sphere (larger than the 20 mm elbow sphere), the
//     rings on the table, the labels (name, |F| to 0.1 N, mode; no two clash: their anchor boxes,
//     12 mm per character wide and a 35 mm row high, side by side 10 mm apart or a row apart
//     at every sample), the contact spheres on their
//     constraint value C or gap (1e-9 m), the hand spheres on /hand (exact), and /hand_points
//     coloured purple (actual) and orange (desired); the layout's legends never float over a
//     plot and no tab holds more than two plots.
//
// Prints one JSON summary on stdout; exit 0 if every check passed, 1 if one failed (each
// failure on stderr), 2 on bad input.

import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

import { McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import foxgloveInternal from "@foxglove/schemas/internal.js";
import Ajv from "ajv";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";

const { foxgloveMessageSchemas, foxgloveEnumSchemas, generateProto } = foxgloveInternal;
const here = dirname(fileURLToPath(import.meta.url));
const failures = [];
const fail = (msg) => failures.push(msg);
const TOL = 1e-9;
// a label's anchor box at the default views' scale (schemas/src/markers/labels.rs): 12 mm per
// character wide, a 35 mm row high, 10 mm apart side by side
const LABEL_CHAR_WIDTH_M = 0.012;
const LABEL_ROW_M = 0.035;
const LABEL_GAP_M = 0.01;

// the lead's colours (DECISIONS.md), as Foxglove RGB in [0, 1]
const hex = (h) => [1, 3, 5].map((k) => parseInt(h.slice(k, k + 2), 16) / 255);
const MODE_COLORS = {
  separated: hex("#9e9e9e"),
  sticking: hex("#2ca02c"),
  sliding: hex("#ff7f0e"),
  pushing: hex("#1f77b4"),
  pulling: hex("#d62728"),
};
const MODE_BY_CODE = ["separated", "sticking", "sliding"];
const HAND_ACTUAL = [0x94, 0x67, 0xbd, 255];
const HAND_DESIRED = [0xff, 0x7f, 0x0e, 255];

const NUMERIC_OR_STRING = new Set(["string", "bool", "double", "float", "int32", "uint32", "sint32", "fixed32", "sfixed32", "int64", "uint64", "sint64", "fixed64", "sfixed64"]);
const NUMERIC = new Set(["double", "float", "int32", "uint32", "sint32", "fixed32", "sfixed32", "int64", "uint64", "sint64", "fixed64", "sfixed64"]);

async function readMcap(path, decompressHandlers) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(readFileSync(path));
  const schemas = new Map();
  const channels = new Map();
  const messages = new Map(); // topic -> [{logTime, data}]
  const metadata = new Map();
  let rec;
  while ((rec = reader.nextRecord())) {
    if (rec.type === "Schema") schemas.set(rec.id, rec);
    else if (rec.type === "Channel") {
      channels.set(rec.id, rec);
      // the summary section repeats the channels
      if (!messages.has(rec.topic)) messages.set(rec.topic, []);
    } else if (rec.type === "Message") {
      const ch = channels.get(rec.channelId);
      messages.get(ch.topic).push({ logTime: rec.logTime, data: rec.data });
    } else if (rec.type === "Metadata") metadata.set(rec.name, rec.metadata);
  }
  if (!reader.done()) throw new Error(`${path}: the MCAP stream ended early`);
  // one protobufjs type per protobuf channel, from its embedded FileDescriptorSet
  const types = new Map();
  for (const ch of channels.values()) {
    const s = schemas.get(ch.schemaId);
    if (s?.encoding === "protobuf") {
      const root = protobuf.Root.fromDescriptor(descriptor.FileDescriptorSet.decode(s.data));
      types.set(ch.topic, { type: root.lookupType(s.name), name: s.name, root });
    } else if (s) types.set(ch.topic, { type: undefined, name: s.name, encoding: s.encoding });
  }
  return { path, channels, messages, metadata, types };
}

function decodeAll(rec, topic) {
  rec.decoded ??= new Map();
  if (!rec.decoded.has(topic)) rec.decoded.set(topic, decodeTopic(rec, topic));
  return rec.decoded.get(topic);
}

function decodeTopic(rec, topic) {
  const t = rec.types.get(topic)?.type;
  if (!t) return [];
  return rec.messages.get(topic).map((m) => ({
    logTime: m.logTime,
    msg: t.toObject(t.decode(m.data), { longs: Number, defaults: true, arrays: true }),
  }));
}

// --- (a) the layout
function checkLayout(layout) {
  const schema = JSON.parse(readFileSync(join(here, "layout.schema.json"), "utf8"));
  const ajv = new Ajv({ allErrors: true, strict: true, allowUnionTypes: true });
  const validate = ajv.compile(schema);
  if (!validate(layout)) {
    for (const e of validate.errors) fail(`layout: ${e.instancePath || "/"} ${e.message} ${JSON.stringify(e.params)}`);
  }
  // the mosaic tree's leaves, and those of each Tab panel's tabs
  const leaves = [];
  const walk = (n) => {
    if (typeof n === "string") {
      leaves.push(n);
      for (const t of layout.configById?.[n]?.tabs ?? []) walk(t.layout);
    } else if (n) {
      walk(n.first);
      walk(n.second);
    }
  };
  walk(layout.layout);
  const ids = Object.keys(layout.configById ?? {});
  if (JSON.stringify([...leaves].sort()) !== JSON.stringify([...ids].sort())) {
    fail(`layout: the mosaic tree names ${JSON.stringify(leaves)} but configById has ${JSON.stringify(ids)}`);
  }
  // readable (issue 27): no legend floats over its plot; at most two plots in a tab
  for (const [id, c] of Object.entries(layout.configById ?? {})) {
    if (id.startsWith("Plot!") && c.legendDisplay === "floating") fail(`layout: ${id}: its legend floats over the data`);
    for (const t of c.tabs ?? []) {
      const inTab = [];
      const w = (n) => (typeof n === "string" ? inTab.push(n) : n && (w(n.first), w(n.second)));
      w(t.layout);
      const plots = inTab.filter((p) => p.startsWith("Plot!")).length;
      if (plots > 2) fail(`layout: ${id}: tab ${t.title} has ${plots} plots (at most 2)`);
      if (inTab.length > 3) fail(`layout: ${id}: tab ${t.title} has ${inTab.length} panels (at most 2 plots and a band or table panel)`);
    }
  }
  const series = Object.values(layout.configById ?? {}).flatMap((c) => (c.paths ?? []).filter((p) => p.value.startsWith("/")));
  return { panels: ids.length, tabs: Object.values(layout.configById ?? {}).reduce((n, c) => n + (c.tabs?.length ?? 0), 0), series: series.length };
}

// A plot path `/topic.a.b[k]` -> {topic, steps: [{field, index}]}; a number is a reference line.
function parsePath(value) {
  if (!Number.isNaN(Number.parseFloat(value))) return undefined;
  const m = /^(\/[^.]+)\.(.+)$/.exec(value);
  if (!m) throw new Error(`plot path ${value}: not /topic.field`);
  const steps = m[2].split(".").map((s) => {
    const f = /^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$/.exec(s);
    if (!f) throw new Error(`plot path ${value}: bad step ${s}`);
    return { field: f[1], index: f[2] === undefined ? undefined : Number(f[2]) };
  });
  return { topic: m[1], steps };
}

// Resolve the steps in a protobufjs type: the leaf must be numeric, indices only on repeated.
function resolveInSchema(type, steps, value, leafTypes = NUMERIC) {
  let t = type;
  for (const [k, s] of steps.entries()) {
    const f = t.fields[s.field];
    if (!f) return `${value}: no field ${s.field} in ${t.fullName}`;
    f.resolve();
    if ((s.index !== undefined) !== f.repeated) return `${value}: ${s.field} is ${f.repeated ? "repeated (needs an index)" : "not repeated"}`;
    if (k === steps.length - 1) return leafTypes.has(f.type) ? undefined : `${value}: ${s.field} is ${f.type}, not ${leafTypes === NUMERIC ? "numeric" : "a number or a string"}`;
    if (!f.resolvedType || !(f.resolvedType instanceof protobuf.Type)) return `${value}: ${s.field} is not a message`;
    t = f.resolvedType;
  }
  return undefined;
}

function valueAt(msg, steps) {
  let v = msg;
  for (const s of steps) {
    v = v?.[s.field];
    if (s.index !== undefined) v = v?.[s.index];
  }
  return v;
}

function layoutTopics(layout) {
  const topics = new Set();
  const paths = [];
  for (const cfg of Object.values(layout.configById)) {
    for (const t of Object.keys(cfg.topics ?? {})) topics.add(t);
    // a Table panel shows the latest message of its topic
    if (typeof cfg.topicPath === "string") topics.add(cfg.topicPath);
    // a State Transitions panel's bands take numbers and strings (mode codes, event kinds)
    const state = Object.entries(layout.configById).some(([id, c]) => c === cfg && id.startsWith("StateTransitions!"));
    for (const p of cfg.paths ?? []) {
      const parsed = parsePath(p.value);
      if (parsed) {
        topics.add(parsed.topic);
        paths.push({ value: p.value, state, ...parsed });
      }
    }
  }
  return { topics: [...topics].sort(), paths };
}

// --- (b) topics and plot paths against the recordings
function checkPaths(layout, recs) {
  const { topics, paths } = layoutTopics(layout);
  for (const rec of recs) {
    for (const t of topics) {
      if (!rec.messages.has(t)) fail(`${rec.path}: the layout names ${t}, the recording has no such topic`);
      else if (rec.messages.get(t).length === 0) fail(`${rec.path}: the layout names ${t}, the recording has no message on it`);
    }
  }
  let resolved = 0;
  for (const p of paths) {
    let numbers = 0;
    for (const rec of recs) {
      const type = rec.types.get(p.topic)?.type;
      if (!type) continue;
      const err = resolveInSchema(type, p.steps, p.value, p.state ? NUMERIC_OR_STRING : NUMERIC);
      if (err) {
        fail(`${rec.path}: ${err}`);
        continue;
      }
      for (const { msg } of decodeAll(rec, p.topic)) {
        const v = valueAt(msg, p.steps);
        if ((typeof v === "number" && Number.isFinite(v)) || (p.state && typeof v === "string" && v !== "")) numbers++;
      }
    }
    if (numbers === 0) fail(`plot path ${p.value}: no recording gives it a finite number`);
    else resolved++;
  }
  return { topics: topics.length, plot_paths: paths.length, plot_paths_with_data: resolved };
}

// The embedded foxglove.* descriptors against @foxglove/schemas: every field of ours exists there
// with the same number, type and label (parsed from the .proto text it generates).
function checkAgainstFoxgloveSchemas(rec, topic) {
  const info = rec.types.get(topic);
  const short = info.name.replace(/^foxglove\./, "");
  const seen = new Set();
  const compare = (ours) => {
    const name = ours.name;
    // google.protobuf.Timestamp / Duration: @foxglove/schemas' protoEquivalent, not its own
    if (ours.fullName.startsWith(".google.protobuf.")) return;
    if (seen.has(name)) return;
    seen.add(name);
    const def = foxgloveMessageSchemas[name];
    if (!def) return; // google.protobuf.Timestamp and the like
    const proto = generateProto(def, Object.values(foxgloveEnumSchemas).filter((e) => e.parentSchemaName === name));
    const theirs = protobuf.parse(proto, { keepCase: true }).root.lookupType(`foxglove.${name}`);
    for (const f of Object.values(ours.fields)) {
      const g = theirs.fields[f.name];
      if (!g) fail(`${rec.path}: ${topic}: field ${name}.${f.name} is not in @foxglove/schemas`);
      else if (g.id !== f.id || g.repeated !== f.repeated || g.type.replace(/^.*\./, "") !== f.type.replace(/^.*\./, ""))
        fail(`${rec.path}: ${topic}: ${name}.${f.name} is #${f.id} ${f.type}${f.repeated ? "[]" : ""}, @foxglove/schemas says #${g.id} ${g.type}${g.repeated ? "[]" : ""}`);
      f.resolve();
      if (f.resolvedType instanceof protobuf.Type) compare(f.resolvedType);
    }
  };
  compare(info.type);
  if (!seen.has(short)) fail(`${topic}: schema ${info.name} not compared`);
  return seen.size;
}

const close = (a, b, tol) => Math.abs(a - b) <= tol;
const sameRgb = (c, rgb) => close(c.r, rgb[0], 1e-12) && close(c.g, rgb[1], 1e-12) && close(c.b, rgb[2], 1e-12);
function rotateX(q) {
  // the image of +x under the unit quaternion q
  const { x, y, z, w } = q;
  return [1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)];
}

// --- (c) the scene entities
function checkScene(rec) {
  const run = rec.metadata.get("run");
  const contacts = JSON.parse(run.get("contacts") ?? "[]");
  const sceneJson = JSON.parse(rec.metadata.get("scene").get("json"));
  const planeOf = new Map();
  for (const c of sceneJson.contacts ?? []) planeOf.set(c.name, c.plane);
  for (const p of sceneJson.table?.points ?? []) planeOf.set(p.name, sceneJson.table.plane);
  // the contacts as they ran (record `contacts`, runs with a non-bilateral contact): also the
  // capsules' ends `<name>/0`, `<name>/1` and the table's contacts from URDF collisions, which
  // the scene does not list by name
  for (const c of JSON.parse(rec.metadata.get("contacts")?.get("contacts") ?? "[]")) planeOf.set(c.name, { normal: c.normal, offset: c.offset });
  const distinct = new Set([...planeOf.values()].map((p) => JSON.stringify([p.normal, p.offset ?? 0])));
  const hybrid = rec.messages.has("/contacts");
  const out = { run: run.get("run"), contacts: contacts.length, hybrid };

  for (const t of ["/scene", "/contact_markers"]) out[`${t}_types_compared`] = checkAgainstFoxgloveSchemas(rec, t);

  // /scene: one box per distinct plane (top face on the plane), the target path
  const scene = decodeAll(rec, "/scene");
  if (scene.length !== 1 || scene[0].logTime !== 0n) fail(`${rec.path}: /scene has ${scene.length} messages (want 1 at t = 0)`);
  const ents = scene[0]?.msg.entities ?? [];
  const tables = ents.filter((e) => e.id.startsWith("table/"));
  if (tables.length !== distinct.size) fail(`${rec.path}: /scene has ${tables.length} tables, the scene ${distinct.size} distinct planes`);
  for (const e of tables) {
    const n = JSON.parse(e.metadata.find((kv) => kv.key === "normal").value);
    const d = Number(e.metadata.find((kv) => kv.key === "offset_m").value);
    const cube = e.cubes[0];
    const top = rotateZ(cube.pose.orientation);
    const c = cube.pose.position;
    const topCentre = [c.x + (top[0] * cube.size.z) / 2, c.y + (top[1] * cube.size.z) / 2, c.z + (top[2] * cube.size.z) / 2];
    const gap = n[0] * topCentre[0] + n[1] * topCentre[1] + n[2] * topCentre[2] - d;
    if (!close(gap, 0, TOL)) fail(`${rec.path}: ${e.id}: top face ${gap} m off its plane`);
    if (e.frame_id !== "world") fail(`${rec.path}: ${e.id}: frame ${e.frame_id}`);
  }
  const path = ents.find((e) => e.id === "target_path");
  const hand = decodeAll(rec, "/hand");
  if (!path) fail(`${rec.path}: /scene has no target_path`);
  else {
    const p0 = path.lines[0].points[0];
    const d0 = hand[0].msg.desired;
    if (!(p0.x === d0.x && p0.y === d0.y && p0.z === d0.z)) fail(`${rec.path}: target path starts at ${JSON.stringify(p0)}, /hand desired at t = 0 is ${JSON.stringify(d0)}`);
    out.target_path_points = path.lines[0].points.length;
  }
  out.tables = tables.length;

  // /contact_markers against /constraints (bilateral) or /contacts (hybrid) and /hand, sample by sample
  const markers = decodeAll(rec, "/contact_markers");
  const forces = decodeAll(rec, hybrid ? "/contacts" : "/constraints");
  const constraints = decodeAll(rec, "/constraints");
  if (markers.length !== hand.length) fail(`${rec.path}: ${markers.length} /contact_markers, ${hand.length} /hand`);
  const modesSeen = {};
  let arrows = 0;
  let labels = 0;
  let minLabelClearance = Infinity;
  let nonzero = 0;
  let minOutside = Infinity;
  let maxArrowErr = 0;
  // the one force scale of the scene, on /scene
  const legend = ents.find((e) => e.id === "legend/force_scale");
  const sceneScale = legend ? Number(legend.metadata.find((kv) => kv.key === "scale_m_per_n").value) : NaN;
  if (contacts.length > 0 && !(sceneScale > 0)) fail(`${rec.path}: /scene has no legend/force_scale with a scale`);
  if (legend) {
    const a = legend.arrows[0];
    const bar = Number(legend.metadata.find((kv) => kv.key === "bar_force_n").value);
    if (!close(a.shaft_length + a.head_length, bar * sceneScale, TOL)) fail(`${rec.path}: the scale bar is ${a.shaft_length + a.head_length} m for ${bar} N at ${sceneScale} m/N`);
    if (!legend.texts[0]?.text.startsWith(`${bar} N = `)) fail(`${rec.path}: the scale bar's text is ${JSON.stringify(legend.texts[0]?.text)}`);
  }
  out.force_scale_m_per_n = sceneScale;
  // a separated contact is not drawn: its two entities are deleted (MATCHING_ID, stamped at the
  // sample) in the message of the sample where it separates (and in the first one), and absent
  // while it stays separated; a touching one is in every message (schemas::markers::ContactMarkers)
  const drawnBefore = new Map(contacts.map((name) => [name, true]));
  let separatedChecked = 0;
  let deletionsChecked = 0;
  for (const [i, { logTime, msg }] of markers.entries()) {
    const f = forces[i]?.msg;
    const c = constraints[i]?.msg;
    if (forces[i]?.logTime !== logTime) {
      fail(`${rec.path}: /contact_markers and the forces are not sample for sample at ${logTime}`);
      break;
    }
    const deleted = new Map((msg.deletions ?? []).map((d) => [d.id, d]));
    const wantIds = [];
    const labelBoxes = [];
    for (const [k, name] of contacts.entries()) {
      const fn = f.normal_force[k];
      const ft = hybrid ? [f.friction_force_t1[k], f.friction_force_t2[k]] : [0, 0];
      const code = hybrid ? f.mode[k] : 3;
      const mode = code === 3 ? (fn < 0 ? "pulling" : "pushing") : MODE_BY_CODE[code];
      modesSeen[mode] = (modesSeen[mode] ?? 0) + 1;
      const ids = [`contact/${name}`, `force/${name}`];
      const drawnHere = msg.entities.filter((e) => ids.includes(e.id)).length;
      const deletions = ids.filter((id) => deleted.has(id));
      if (mode === "separated") {
        if (drawnHere !== 0) fail(`${rec.path}: /contact_markers at ${logTime}: ${name} is separated and drawn`);
        const want = drawnBefore.get(name) ? 2 : 0;
        if (deletions.length !== want) fail(`${rec.path}: /contact_markers at ${logTime}: ${deletions.length} deletions of ${name}, want ${want} (separated, ${want ? "drawn" : "not drawn"} before)`);
        for (const id of deletions) {
          const d = deleted.get(id);
          const t = d.timestamp ? Number(d.timestamp.seconds ?? d.timestamp.sec) * 1e9 + Number(d.timestamp.nanos ?? d.timestamp.nsec) : -1;
          if (d.type !== 0 || t !== Number(logTime)) fail(`${rec.path}: /contact_markers at ${logTime}: deletion of ${id} of type ${d.type} stamped ${t} ns`);
          deletionsChecked++;
        }
        drawnBefore.set(name, false);
        separatedChecked++;
        continue;
      }
      if (deletions.length !== 0) fail(`${rec.path}: /contact_markers at ${logTime}: ${name} is ${mode} and deleted`);
      drawnBefore.set(name, true);
      wantIds.push(...ids);
      const marker = msg.entities.find((e) => e.id === ids[0]);
      const arrowEnt = msg.entities.find((e) => e.id === ids[1]);
      if (!marker || !arrowEnt) {
        fail(`${rec.path}: /contact_markers at ${logTime}: ${name} is ${mode} and not drawn`);
        continue;
      }
      if (!sameRgb(marker.spheres[0].color, MODE_COLORS[mode])) fail(`${rec.path}: ${marker.id} at ${logTime}: colour ${JSON.stringify(marker.spheres[0].color)} for mode ${mode}`);
      const a = arrowEnt.arrows[0];
      if (!sameRgb(a.color, MODE_COLORS[mode])) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: arrow colour for mode ${mode}`);
      const scale = Number(arrowEnt.metadata.find((kv) => kv.key === "scale_m_per_n").value);
      const minLen = Number(arrowEnt.metadata.find((kv) => kv.key === "min_length_m")?.value);
      if (!(minLen > 0)) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: no min_length_m in its metadata`);
      if (scale !== sceneScale) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: scale ${scale} m/N, /scene says ${sceneScale}`);
      const len = a.shaft_length + a.head_length;
      const norm = Math.hypot(fn, ft[0], ft[1]);
      // |F| x scale, at least the shortest length for a nonzero force, none for no force
      const want = norm > 0 ? Math.max(norm * scale, minLen) : 0;
      const err = Math.abs(len - want);
      maxArrowErr = Math.max(maxArrowErr, err);
      if (err > TOL) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: length ${len} m, max(|F| x scale, ${minLen}) = ${want} m`);
      // the arrow's normal component has f_n's sign and share of |F|; the sphere is at the
      // contact point (C or gap); the arrow starts on the plane, below or above the sphere
      const plane = planeOf.get(name);
      const n = plane.normal;
      const d = plane.offset ?? 0;
      const dir = rotateX(a.pose.orientation);
      if (norm > 0) {
        const fnDrawn = norm * (dir[0] * n[0] + dir[1] * n[1] + dir[2] * n[2]);
        if (!close(fnDrawn, fn, TOL * Math.max(1, Math.abs(fn)))) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: normal component ${fnDrawn} N, f_n = ${fn} N`);
      }
      const p = marker.spheres[0].pose.position;
      const cq = n[0] * p.x + n[1] * p.y + n[2] * p.z - d;
      const wantC = hybrid ? f.gap[k] : c.position[k];
      if (!close(cq, wantC, TOL)) fail(`${rec.path}: ${marker.id} at ${logTime}: sphere at C = ${cq} m, recorded ${wantC} m`);
      const tail = a.pose.position;
      const tq = n[0] * tail.x + n[1] * tail.y + n[2] * tail.z - d;
      const along = Math.hypot(tail.x - (p.x - cq * n[0]), tail.y - (p.y - cq * n[1]), tail.z - (p.z - cq * n[2]));
      if (!close(tq, 0, TOL) || !close(along, 0, TOL)) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: the arrow starts ${tq} m off the plane, ${along} m from the point's projection`);
      // visible: a nonzero force's arrow leaves the marker sphere by at least 20 mm
      const r = marker.spheres[0].size.x / 2;
      if (!(r > 0.02)) fail(`${rec.path}: ${marker.id}: sphere radius ${r} m, not larger than the 20 mm elbow sphere`);
      if (norm > 0) {
        const tip = [tail.x + len * dir[0], tail.y + len * dir[1], tail.z + len * dir[2]];
        const outside = lengthOutsideBall([tail.x, tail.y, tail.z], tip, [p.x, p.y, p.z], r);
        minOutside = Math.min(minOutside, outside);
        if (!(outside >= 0.02)) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: |F| = ${norm} N drawn ${len} m, only ${outside} m outside its ${r} m marker`);
        nonzero++;
      }
      // the ring on the table around the point's projection, in the mode's colour
      const ring = marker.lines[0];
      const rp = ring?.pose.position;
      if (!ring || !close(n[0] * rp.x + n[1] * rp.y + n[2] * rp.z - d, 0, TOL) || !sameRgb(ring.color, MODE_COLORS[mode])) fail(`${rec.path}: ${marker.id} at ${logTime}: no ring on the table in the mode's colour`);
      // the label: name, |F| to 0.1 N, mode
      const text = arrowEnt.texts[0]?.text ?? "";
      const m = /^(\S+) (\S+) N (.+)$/.exec(text);
      if (!m || m[1] !== name || Math.abs(Number(m[2]) - norm) > 0.05 + 1e-9 * norm) fail(`${rec.path}: ${arrowEnt.id} at ${logTime}: label ${JSON.stringify(text)} for |F| = ${norm} N`);
      else labels++;
      const lp = arrowEnt.texts[0]?.pose?.position;
      if (lp) labelBoxes.push({ name, x: lp.x, y: lp.y, z: lp.z, half: 0.5 * [...text].length * LABEL_CHAR_WIDTH_M });
      arrows++;
    }
    // no two labels clash: side by side (horizontal gap) or a row apart (schemas::markers::labels)
    for (let a = 0; a < labelBoxes.length; a++) {
      for (let b = 0; b < a; b++) {
        const [p, q] = [labelBoxes[a], labelBoxes[b]];
        const across = Math.hypot(p.x - q.x, p.y - q.y) - p.half - q.half - LABEL_GAP_M;
        const up = Math.abs(p.z - q.z) - LABEL_ROW_M;
        const clearance = Math.max(across, up);
        minLabelClearance = Math.min(minLabelClearance, clearance);
        if (clearance < -1e-9) fail(`${rec.path}: /contact_markers at ${logTime}: the labels of ${q.name} and ${p.name} overlap (${-clearance} m)`);
      }
    }
    wantIds.push("hand/actual", "hand/desired");
    const ids = msg.entities.map((e) => e.id);
    if (ids.join() !== wantIds.join()) fail(`${rec.path}: /contact_markers at ${logTime} has entities ${ids.join()}, want ${wantIds.join()}`);
    const [actual, desired] = msg.entities.slice(-2);
    const h = hand[i].msg;
    const pa = actual.spheres[0].pose.position;
    const pd = desired.spheres[0].pose.position;
    if (!(pa.x === h.actual.x && pa.y === h.actual.y && pa.z === h.actual.z)) fail(`${rec.path}: hand/actual at ${logTime} is not /hand actual`);
    if (!(pd.x === h.desired.x && pd.y === h.desired.y && pd.z === h.desired.z)) fail(`${rec.path}: hand/desired at ${logTime} is not /hand desired`);
    if (!sameRgb(actual.spheres[0].color, hex("#9467bd")) || !sameRgb(desired.spheres[0].color, hex("#ff7f0e"))) fail(`${rec.path}: hand colours at ${logTime}`);
    if (!(actual.spheres[0].size.x / 2 > 0.015)) fail(`${rec.path}: the actual hand's sphere is not larger than the URDF's hand sphere (0.015 m)`);
  }
  out.contact_marker_messages = markers.length;
  out.separated_checked = separatedChecked;
  out.deletions_checked = deletionsChecked;
  out.arrows_checked = arrows;
  out.labels_checked = labels;
  out.min_label_clearance_m = Number.isFinite(minLabelClearance) ? minLabelClearance : null;
  out.nonzero_forces = nonzero;
  out.min_length_outside_marker_m = nonzero ? minOutside : null;
  out.max_arrow_length_error_m = maxArrowErr;
  out.modes = modesSeen;

  // /hand_points: separate RGBA fields, purple then orange
  const pts = decodeAll(rec, "/hand_points");
  for (const { logTime, msg } of pts) {
    const field = (n) => msg.fields.find((f) => f.name === n);
    const [r, g, b, al] = ["red", "green", "blue", "alpha"].map(field);
    if (!r || !g || !b || !al) {
      fail(`${rec.path}: /hand_points at ${logTime} lacks red/green/blue/alpha fields`);
      break;
    }
    const bytes = msg.data;
    for (const [k, want] of [HAND_ACTUAL, HAND_DESIRED].entries()) {
      const o = k * msg.point_stride;
      const got = [bytes[o + r.offset], bytes[o + g.offset], bytes[o + b.offset], bytes[o + al.offset]];
      if (got.join() !== want.join()) {
        fail(`${rec.path}: /hand_points point ${k} at ${logTime} has colour ${got}, want ${want}`);
        break;
      }
    }
  }
  out.hand_points = pts.length;
  return out;
}

// Length of the segment a-b outside the ball (c, r).
function lengthOutsideBall(a, b, c, r) {
  const d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const len = Math.hypot(...d);
  if (len === 0) return 0;
  const u = d.map((x) => x / len);
  const m = [a[0] - c[0], a[1] - c[1], a[2] - c[2]];
  const bq = u[0] * m[0] + u[1] * m[1] + u[2] * m[2];
  const cq = m[0] * m[0] + m[1] * m[1] + m[2] * m[2] - r * r;
  const disc = bq * bq - cq;
  if (disc <= 0) return len;
  const t0 = Math.min(Math.max(-bq - Math.sqrt(disc), 0), len);
  const t1 = Math.min(Math.max(-bq + Math.sqrt(disc), 0), len);
  return len - (t1 - t0);
}

function rotateZ(q) {
  // the image of +z under the unit quaternion q
  const { x, y, z, w } = q;
  return [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)];
}

async function main() {
  const [layoutPath, ...recPaths] = process.argv.slice(2);
  if (!layoutPath || recPaths.length === 0) {
    console.error("usage: node check.mjs LAYOUT.json REC.mcap [REC.mcap ...]");
    process.exit(2);
  }
  const layout = JSON.parse(readFileSync(layoutPath, "utf8"));
  const decompressHandlers = await loadDecompressHandlers();
  const recs = [];
  for (const p of recPaths) recs.push(await readMcap(p, decompressHandlers));
  const summary = { layout: checkLayout(layout), paths: checkPaths(layout, recs), recordings: recs.map(checkScene) };
  // one force scale for every run of the scene
  const scales = new Set(summary.recordings.map((r) => r.force_scale_m_per_n).filter((x) => !Number.isNaN(x)));
  if (scales.size > 1) fail(`the recordings draw forces at ${scales.size} scales: ${[...scales].join(", ")} m/N`);
  summary.failures = failures.length;
  console.log(JSON.stringify(summary, null, 1));
  for (const f of failures.slice(0, 50)) console.error(`FAIL ${f}`);
  if (failures.length > 50) console.error(`... and ${failures.length - 50} more`);
  process.exit(failures.length ? 1 : 0);
}

main().catch((e) => {
  console.error(`error: ${e.stack ?? e}`);
  process.exit(2);
});
