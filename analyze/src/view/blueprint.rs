//! A Rerun blueprint (the viewer's layout) as the chunks of a blueprint store.
//!
//! What the 0.41 Python SDK writes for `rerun.blueprint.Blueprint(...)` (read back from its
//! files; archetypes in `re_sdk_types/definitions/rerun/blueprint` of
//! <https://github.com/rerun-io/rerun>):
//! - `/viewport`: `ViewportBlueprint:root_container`, the UUID of the root container;
//! - `/container/<uuid>`: `ContainerBlueprint` (`container_kind`: 1 tabs, 2 horizontal,
//!   3 vertical, 4 grid; `contents`: `container/<uuid>` or `view/<uuid>`; `col_shares`,
//!   `row_shares`, `display_name`);
//! - `/view/<uuid>`: `ViewBlueprint` (`class_identifier` `3D`, `TimeSeries`, `TextLog`;
//!   `display_name`; `space_origin`), and `/view/<uuid>/ViewContents:query` (entity path
//!   expressions, `+ /a/**`, `- /b`); a 3D view's camera is `/view/<uuid>/EyeControls3D`
//!   (`kind` 2 = orbital, `position`, `look_target`, `eye_up`), a plot's legend
//!   `/view/<uuid>/PlotLegend`;
//! - `/blueprint_panel`, `/selection_panel`, `/time_panel`: `PanelState` (1 hidden,
//!   2 collapsed, 3 expanded), and the time panel's `timeline`;
//! - a plot's fixed y range: `/view/<uuid>/ScalarAxis:range` (`Range1D`, `[f64; 2]`).
//!
//! Every row is on the sequence timeline `blueprint` at 0. UUIDs are made from a seed and a
//! counter, so the same layout gives the same bytes.

use super::chunk::{bool_lists, f32_lists, range_lists, str_lists, u8_lists, uuid_lists, vec3_lists, Chunk, Index};

const CONTAINER: &str = "rerun.blueprint.archetypes.ContainerBlueprint";
const VIEW: &str = "rerun.blueprint.archetypes.ViewBlueprint";
const VIEW_CONTENTS: &str = "rerun.blueprint.archetypes.ViewContents";
const EYE: &str = "rerun.blueprint.archetypes.EyeControls3D";
const LEGEND: &str = "rerun.blueprint.archetypes.PlotLegend";
const AXIS: &str = "rerun.blueprint.archetypes.ScalarAxis";
const VIEWPORT: &str = "rerun.blueprint.archetypes.ViewportBlueprint";
const PANEL: &str = "rerun.blueprint.archetypes.PanelBlueprint";
const TIME_PANEL: &str = "rerun.blueprint.archetypes.TimePanelBlueprint";

/// How a container arranges its children.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContainerKind {
    Tabs = 1,
    Horizontal = 2,
    Vertical = 3,
    Grid = 4,
}

/// The view classes used here (`ViewBlueprint:class_identifier`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewClass {
    Spatial3D,
    TimeSeries,
    TextLog,
}

impl ViewClass {
    pub fn identifier(self) -> &'static str {
        match self {
            ViewClass::Spatial3D => "3D",
            ViewClass::TimeSeries => "TimeSeries",
            ViewClass::TextLog => "TextLog",
        }
    }
}

/// An orbital camera of a 3D view, in the view's origin frame, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eye {
    pub position: [f64; 3],
    pub look_target: [f64; 3],
    pub up: [f64; 3],
}

/// One view.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    pub class: ViewClass,
    pub name: String,
    pub origin: String,
    /// Entity path expressions (`/a/**`, `- /a/b`); empty: `$origin/**`.
    pub contents: Vec<String>,
    pub eye: Option<Eye>,
    /// The y axis range of a time series view (else the viewer fits all data).
    pub y_range: Option<[f64; 2]>,
    /// Where a time series view's legend sits.
    pub legend: Corner,
}

/// A plot legend's corner (`rerun.blueprint.components.Corner2D`: 1 left top, 2 right top,
/// 3 left bottom, 4 right bottom), or hidden.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    LeftTop = 1,
    RightTop = 2,
    LeftBottom = 3,
    RightBottom = 4,
    Hidden = 0,
}

impl View {
    pub fn new(class: ViewClass, name: impl Into<String>, origin: impl Into<String>) -> Self {
        View { class, name: name.into(), origin: origin.into(), contents: Vec::new(), eye: None, y_range: None, legend: Corner::LeftTop }
    }

    pub fn y_range(mut self, range: Option<[f64; 2]>) -> Self {
        self.y_range = range;
        self
    }

    pub fn legend(mut self, corner: Corner) -> Self {
        self.legend = corner;
        self
    }

    pub fn contents(mut self, exprs: impl IntoIterator<Item = String>) -> Self {
        self.contents.extend(exprs);
        self
    }

    pub fn eye(mut self, eye: Eye) -> Self {
        self.eye = Some(eye);
        self
    }
}

/// A node of the layout.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// `active`: the tab shown first (tabs only; the first when `None`).
    Container { kind: ContainerKind, name: Option<String>, shares: Vec<f32>, children: Vec<Node>, active: Option<usize> },
    View(View),
}

impl Node {
    pub fn container(kind: ContainerKind, children: Vec<Node>) -> Node {
        Node::Container { kind, name: None, shares: Vec::new(), children, active: None }
    }

    /// The names of the tabs of the first tab container (depth first), in order.
    pub fn tab_names(&self) -> Vec<String> {
        match self {
            Node::View(_) => Vec::new(),
            Node::Container { kind: ContainerKind::Tabs, children, .. } => children
                .iter()
                .map(|c| match c {
                    Node::View(v) => v.name.clone(),
                    Node::Container { name, .. } => name.clone().unwrap_or_default(),
                })
                .collect(),
            Node::Container { children, .. } => children.iter().map(Node::tab_names).find(|t| !t.is_empty()).unwrap_or_default(),
        }
    }

    /// The same tree opening on the tab named `tab` of its first tab container; `Err` with the
    /// tab names when there is none of that name.
    pub fn open_on(mut self, tab: &str) -> Result<Node, Vec<String>> {
        fn set(n: &mut Node, tab: &str) -> bool {
            match n {
                Node::View(_) => false,
                Node::Container { kind: ContainerKind::Tabs, children, active, .. } => {
                    let k = children.iter().position(|c| match c {
                        Node::View(v) => v.name == tab,
                        Node::Container { name, .. } => name.as_deref() == Some(tab),
                    });
                    *active = k;
                    k.is_some()
                }
                Node::Container { children, .. } => children.iter_mut().any(|c| !c.tab_names().is_empty() && set(c, tab)),
            }
        }
        let names = self.tab_names();
        if set(&mut self, tab) {
            Ok(self)
        } else {
            Err(names)
        }
    }

    /// Column (horizontal) or row (vertical) shares of the children.
    pub fn shares(mut self, s: &[f32]) -> Node {
        if let Node::Container { shares, .. } = &mut self {
            *shares = s.to_vec();
        }
        self
    }

    pub fn named(mut self, n: &str) -> Node {
        if let Node::Container { name, .. } = &mut self {
            *name = Some(n.to_string());
        }
        self
    }

    /// Every view in the tree, depth first.
    pub fn views(&self) -> Vec<&View> {
        match self {
            Node::View(v) => vec![v],
            Node::Container { children, .. } => children.iter().flat_map(Node::views).collect(),
        }
    }
}

struct Ids {
    seed: u64,
    next: u64,
}

impl Ids {
    /// A version-4-shaped UUID from the seed and a counter (deterministic).
    fn next(&mut self) -> [u8; 16] {
        self.next += 1;
        let mut b = [0u8; 16];
        b[..8].copy_from_slice(&self.seed.to_be_bytes());
        b[8..].copy_from_slice(&(self.next.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ self.seed.rotate_left(17)).to_be_bytes());
        b[6] = (b[6] & 0x0f) | 0x40;
        b[8] = (b[8] & 0x3f) | 0x80;
        b
    }
}

fn uuid_text(b: &[u8; 16]) -> String {
    let h: String = b.iter().map(|x| format!("{x:02x}")).collect();
    format!("{}-{}-{}-{}-{}", &h[..8], &h[8..12], &h[12..16], &h[16..20], &h[20..])
}

fn one_str(s: &str) -> arrow_array::ArrayRef {
    str_lists(&[vec![s.to_string()]])
}

fn f3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// The chunks of a blueprint whose root is `root` (views are named by `seed`-derived UUIDs).
pub fn chunks(root: &Node, seed: u64) -> Vec<Chunk> {
    let mut ids = Ids { seed, next: 0 };
    let mut out = Vec::new();
    let root_id = emit(root, &mut ids, &mut out);
    let Some(root_container) = root_id.strip_prefix("container/").map(str::to_string) else {
        // a lone view: wrap it
        let wrapped = Node::container(ContainerKind::Tabs, vec![root.clone()]);
        return chunks(&wrapped, seed);
    };
    let bytes = parse_uuid(&root_container);
    out.push(Chunk::new("/viewport", Index::Blueprint).with(VIEWPORT, "root_container", "rerun.blueprint.components.RootContainer", uuid_lists(&[vec![bytes]])));
    // every panel collapsed (room for the views); the time panel on `sim_time`
    for path in ["/blueprint_panel", "/selection_panel"] {
        out.push(Chunk::new(path, Index::Blueprint).with(PANEL, "state", "rerun.blueprint.components.PanelState", u8_lists(&[vec![2]])));
    }
    out.push(
        Chunk::new("/time_panel", Index::Blueprint)
            .with(TIME_PANEL, "state", "rerun.blueprint.components.PanelState", u8_lists(&[vec![2]]))
            .with(TIME_PANEL, "timeline", "rerun.blueprint.components.TimelineName", str_lists(&[vec![super::chunk::SIM_TIME.to_string()]])),
    );
    out
}

fn parse_uuid(text: &str) -> [u8; 16] {
    let hex: String = text.chars().filter(|c| *c != '-').collect();
    let mut b = [0u8; 16];
    for (k, byte) in b.iter_mut().enumerate() {
        *byte = u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).unwrap_or(0);
    }
    b
}

/// Emits the chunks of `node` and returns how its parent refers to it (`view/<uuid>`,
/// `container/<uuid>`).
fn emit(node: &Node, ids: &mut Ids, out: &mut Vec<Chunk>) -> String {
    let id = uuid_text(&ids.next());
    match node {
        Node::View(v) => {
            let path = format!("/view/{id}");
            out.push(
                Chunk::new(&path, Index::Blueprint)
                    .with(VIEW, "class_identifier", "rerun.blueprint.components.ViewClass", one_str(v.class.identifier()))
                    .with(VIEW, "display_name", "rerun.components.Name", one_str(&v.name))
                    .with(VIEW, "space_origin", "rerun.blueprint.components.ViewOrigin", one_str(&v.origin)),
            );
            let query = if v.contents.is_empty() { vec!["$origin/**".to_string()] } else { v.contents.clone() };
            out.push(Chunk::new(format!("{path}/ViewContents"), Index::Blueprint).with(
                VIEW_CONTENTS,
                "query",
                "rerun.blueprint.components.QueryExpression",
                str_lists(&[query]),
            ));
            if let Some(e) = v.eye {
                out.push(
                    Chunk::new(format!("{path}/EyeControls3D"), Index::Blueprint)
                        .with(EYE, "eye_up", "rerun.components.Vector3D", vec3_lists(&[vec![f3(e.up)]]))
                        .with(EYE, "kind", "rerun.blueprint.components.Eye3DKind", u8_lists(&[vec![2]]))
                        .with(EYE, "look_target", "rerun.components.Position3D", vec3_lists(&[vec![f3(e.look_target)]]))
                        .with(EYE, "position", "rerun.components.Position3D", vec3_lists(&[vec![f3(e.position)]])),
                );
            }
            if let Some([lo, hi]) = v.y_range {
                out.push(
                    Chunk::new(format!("{path}/ScalarAxis"), Index::Blueprint)
                        .with(AXIS, "range", "rerun.components.Range1D", range_lists(lo, hi)),
                );
            }
            if v.class == ViewClass::TimeSeries {
                // the legend in the corner the view asks for (where its data leaves room), or hidden
                let corner = if v.legend == Corner::Hidden { Corner::LeftTop } else { v.legend };
                out.push(
                    Chunk::new(format!("{path}/PlotLegend"), Index::Blueprint)
                        .with(LEGEND, "corner", "rerun.blueprint.components.Corner2D", u8_lists(&[vec![corner as u8]]))
                        .with(LEGEND, "visible", "rerun.components.Visible", bool_lists(&[vec![v.legend != Corner::Hidden]])),
                );
            }
            format!("view/{id}")
        }
        Node::Container { kind, name, shares, children, active } => {
            let contents: Vec<String> = children.iter().map(|c| emit(c, ids, out)).collect();
            let mut chunk = Chunk::new(format!("/container/{id}"), Index::Blueprint)
                .with(CONTAINER, "container_kind", "rerun.blueprint.components.ContainerKind", u8_lists(&[vec![*kind as u8]]))
                .with(CONTAINER, "contents", "rerun.blueprint.components.IncludedContent", str_lists(&[contents.clone()]));
            if let Some(n) = name {
                chunk = chunk.with(CONTAINER, "display_name", "rerun.components.Name", one_str(n));
            }
            if !shares.is_empty() {
                let (field, ty) = match kind {
                    ContainerKind::Vertical => ("row_shares", "rerun.blueprint.components.RowShare"),
                    _ => ("col_shares", "rerun.blueprint.components.ColumnShare"),
                };
                chunk = chunk.with(CONTAINER, field, ty, f32_lists(&[shares.clone()]));
            }
            if *kind == ContainerKind::Tabs {
                if let Some(tab) = contents.get(active.unwrap_or(0)) {
                    chunk = chunk.with(CONTAINER, "active_tab", "rerun.blueprint.components.ActiveTab", one_str(tab));
                }
            }
            out.push(chunk);
            format!("container/{id}")
        }
    }
}
