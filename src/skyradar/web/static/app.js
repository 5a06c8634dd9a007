// skyradar live display: plan view, vertical-speed bands, range-Doppler image, replay controls.
// No build step: plain browser JavaScript talking to the server's /ws WebSocket.
"use strict";

const LEVEL_NAMES = ["none", "preventive", "corrective", "warning"];
const LEVEL_COLOURS = ["#40c0ff", "#ffd700", "#ffa500", "#ff3030"];
const FT = 0.3048;

// history: [time_s, max_level] of every frame drawn, in order (read by the browser test).
const state = { info: null, frame: null, playing: true, framesSeen: 0, history: [], socket: null };
window.skyradar = state; // for tests and the console

const $ = (id) => document.getElementById(id);

function connect() {
  const proto = location.protocol === "https:" ? "wss" : "ws";
  const ws = new WebSocket(`${proto}://${location.host}/ws`);
  state.socket = ws;
  ws.onmessage = (ev) => handle(JSON.parse(ev.data));
  ws.onopen = () => setStatus("live");
  ws.onclose = () => setStatus("closed");
}

function send(msg) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify(msg));
}

function setStatus(s) {
  $("status").dataset.state = s;
  $("status").textContent = s;
}

function handle(msg) {
  if (msg.type === "info") {
    state.info = msg;
    $("run").textContent = msg.run + (msg.growing ? " (being written)" : "");
    $("source").textContent = msg.traffic_source;
    $("rmax").textContent = Math.round(msg.range_max_m);
    $("vlim").textContent = msg.v_lim_mps.toFixed(1);
    $("seek").max = Math.max(msg.n_total - 1, 0);
    $("nframes").textContent = msg.n_total;
    state.playing = msg.playing;
    $("play").textContent = msg.playing ? "pause" : "play";
    $("speed").value = String(msg.speed);
  } else if (msg.type === "frame") {
    state.frame = msg;
    state.framesSeen += 1;
    state.history.push([msg.time_s, msg.max_level]);
    render(msg);
  } else if (msg.type === "end") {
    setStatus("ended");
    state.playing = false;
    $("play").textContent = "play";
  }
}

function render(f) {
  $("time").textContent = f.time_s.toFixed(1);
  $("time").dataset.time = f.time_s;
  $("frame").textContent = f.index;
  $("seek").value = f.index;
  if (f.rd_png) $("rd").src = f.rd_png;
  drawPlan(f);
  drawVsTape(f);
  renderTable(f);
  renderAlert(f);
  renderAdvice(f);
}

// A range-only track (one channel) has no bearing and no height: sector -1, rel_alt_m null.
function clock(sector) {
  if (sector === null || sector === undefined || sector < 0) return "no bearing";
  return `${sector === 0 ? 12 : sector} o'clock`;
}

function relAltText(m) {
  if (m === null || m === undefined) return "height ?";
  const h = Math.round(m / FT / 100);
  return (h >= 0 ? "+" : "-") + String(Math.abs(h)).padStart(2, "0");
}

function trendArrow(climb) {
  if (climb === null || climb === undefined) return "";
  if (climb > 500 * FT / 60) return "\u2191";
  if (climb < -500 * FT / 60) return "\u2193";
  return "";
}

function drawPlan(f) {
  const cv = $("plan");
  const g = cv.getContext("2d");
  const W = cv.width, H = cv.height, cx = W / 2, cy = H / 2, R = W / 2 - 40;
  const scaleM = parseFloat($("scale").value);
  const k = R / scaleM;
  const own = f.ownship;
  const hdg = own ? own.heading_deg : 0;
  g.clearRect(0, 0, W, H);
  // Range rings and compass ring (heading up).
  g.strokeStyle = "#333"; g.fillStyle = "#777"; g.font = "11px sans-serif"; g.lineWidth = 1;
  for (const frac of [0.2, 0.5, 1.0]) {
    g.beginPath(); g.arc(cx, cy, R * frac, 0, 2 * Math.PI); g.stroke();
    g.fillText(`${parseFloat((scaleM * frac / 1000).toFixed(1))} km`, cx - 40, cy - R * frac + 12);
  }
  const arcAngle = (deg) => ((deg - hdg - 90) * Math.PI) / 180;
  // Heading bands on the outer ring: green free, red conflicting, marker at the preferred heading.
  const ringR = R + 14;
  g.lineWidth = 8;
  g.strokeStyle = "#1f7a1f";
  g.beginPath(); g.arc(cx, cy, ringR, 0, 2 * Math.PI); g.stroke();
  const adv = f.advice;
  if (adv && adv.heading_bands_deg) {
    g.strokeStyle = "#d02020";
    const b = adv.heading_bands_deg;
    for (let i = 0; i + 1 < b.length; i += 2) {
      g.beginPath(); g.arc(cx, cy, ringR, arcAngle(b[i]), arcAngle(b[i + 1])); g.stroke();
    }
    if (adv.preferred_heading_deg !== null) {
      const a = arcAngle(adv.preferred_heading_deg);
      g.fillStyle = "#6f6";
      g.beginPath();
      g.moveTo(cx + (ringR - 10) * Math.cos(a), cy + (ringR - 10) * Math.sin(a));
      g.lineTo(cx + (ringR + 8) * Math.cos(a + 0.04), cy + (ringR + 8) * Math.sin(a + 0.04));
      g.lineTo(cx + (ringR + 8) * Math.cos(a - 0.04), cy + (ringR + 8) * Math.sin(a - 0.04));
      g.fill();
    }
  }
  g.lineWidth = 1;
  g.fillStyle = "#aaa"; g.font = "12px sans-serif";
  for (let d = 0; d < 360; d += 30) {
    const a = arcAngle(d);
    const label = d === 0 ? "N" : d === 90 ? "E" : d === 180 ? "S" : d === 270 ? "W" : String(d / 10);
    g.fillText(label, cx + (ringR + 14) * Math.cos(a) - 5, cy + (ringR + 14) * Math.sin(a) + 4);
  }
  // Own-ship chevron at the centre, pointing up.
  g.fillStyle = "#fff";
  g.beginPath(); g.moveTo(cx, cy - 12); g.lineTo(cx + 8, cy + 8); g.lineTo(cx, cy + 3); g.lineTo(cx - 8, cy + 8);
  g.closePath(); g.fill();
  // Intruders: TCAS-like symbols by level, relative altitude (hundreds of ft) and trend arrow.
  const h = (hdg * Math.PI) / 180;
  for (const t of f.traffic) {
    if (t.rel_north_m === undefined || t.rel_north_m === null) continue;
    const fwd = t.rel_north_m * Math.cos(h) + t.rel_east_m * Math.sin(h);
    const right = -t.rel_north_m * Math.sin(h) + t.rel_east_m * Math.cos(h);
    let x = cx + right * k, y = cy - fwd * k;
    const out = Math.hypot(x - cx, y - cy) > R;
    if (out) { // clamp to the edge so off-scale alerts stay visible
      const s = R / Math.hypot(x - cx, y - cy);
      x = cx + (x - cx) * s; y = cy + (y - cy) * s;
    }
    drawSymbol(g, x, y, t.level);
    g.fillStyle = LEVEL_COLOURS[t.level] || "#fff";
    g.font = "12px monospace";
    g.fillText(relAltText(t.rel_alt_m) + trendArrow(t.climb_rate_mps), x + 10, y - 8);
    g.fillText(`#${t.track_id}`, x + 10, y + 14);
  }
}

function drawSymbol(g, x, y, level) {
  const c = LEVEL_COLOURS[level] || "#fff";
  g.strokeStyle = c; g.fillStyle = c; g.lineWidth = 2;
  g.beginPath();
  if (level >= 3) {
    g.rect(x - 7, y - 7, 14, 14); g.fill();
  } else if (level === 2) {
    g.arc(x, y, 7, 0, 2 * Math.PI); g.fill();
  } else {
    g.moveTo(x, y - 8); g.lineTo(x + 8, y); g.lineTo(x, y + 8); g.lineTo(x - 8, y); g.closePath();
    if (level === 1) g.fill(); else g.stroke();
  }
  g.lineWidth = 1;
}

function drawVsTape(f) {
  const cv = $("vstape");
  const g = cv.getContext("2d");
  const W = cv.width, H = cv.height, top = 20, bot = H - 20, vmax = 10;
  const y = (vs) => top + ((vmax - vs) / (2 * vmax)) * (bot - top);
  g.clearRect(0, 0, W, H);
  g.fillStyle = "#1f7a1f"; g.fillRect(30, top, 14, bot - top);
  const adv = f.advice;
  const paint = (bands, colour) => {
    if (!bands) return;
    g.fillStyle = colour;
    for (let i = 0; i + 1 < bands.length; i += 2) {
      const y0 = y(Math.min(bands[i + 1], vmax)), y1 = y(Math.max(bands[i], -vmax));
      g.fillRect(30, y0, 14, y1 - y0);
    }
  };
  if (adv) { paint(adv.vs_bands_mps, "#d02020"); paint(adv.terrain_vs_bands_mps, "#8b5a2b"); }
  g.fillStyle = "#aaa"; g.font = "11px sans-serif";
  for (const v of [-10, -5, 0, 5, 10]) g.fillText(String(v), 2, y(v) + 4);
  g.fillText("m/s", 50, top - 6);
  if (f.ownship) {
    g.fillStyle = "#fff";
    const yo = y(Math.max(-vmax, Math.min(vmax, f.ownship.vs_mps)));
    g.beginPath(); g.moveTo(46, yo); g.lineTo(58, yo - 6); g.lineTo(58, yo + 6); g.fill();
  }
  if (adv && adv.preferred_vs_mps !== null && adv.preferred_vs_mps !== undefined) {
    g.fillStyle = "#6f6";
    const yp = y(Math.max(-vmax, Math.min(vmax, adv.preferred_vs_mps)));
    g.fillRect(28, yp - 2, 18, 4);
  }
}

function renderTable(f) {
  const body = $("traffic").querySelector("tbody");
  body.textContent = "";
  const rows = [...f.traffic].sort((a, b) => b.level - a.level || a.range_m - b.range_m);
  for (const t of rows) {
    const tr = document.createElement("tr");
    tr.dataset.track = t.track_id;
    tr.dataset.level = t.level;
    const cells = [t.track_id, LEVEL_NAMES[t.level] || t.level, t.flarm_level, clock(t.sector),
      Math.round(t.range_m), relAltText(t.rel_alt_m) + trendArrow(t.climb_rate_mps),
      t.tcpa_s === null ? "-" : t.tcpa_s.toFixed(0)];
    for (const c of cells) {
      const td = document.createElement("td");
      td.textContent = c;
      tr.appendChild(td);
    }
    body.appendChild(tr);
  }
}

function renderAlert(f) {
  const el = $("alert");
  const top = [...f.traffic].sort((a, b) => b.level - a.level || a.range_m - b.range_m)[0];
  el.dataset.level = f.max_level;
  if (!top || f.max_level === 0) {
    el.textContent = f.traffic.length ? `${f.traffic.length} traffic, no alert` : "no traffic";
    return;
  }
  el.dataset.track = top.track_id;
  el.textContent = `${LEVEL_NAMES[top.level].toUpperCase()}  #${top.track_id}  ${clock(top.sector)}  `
    + `${relAltText(top.rel_alt_m)}${trendArrow(top.climb_rate_mps)}  ${Math.round(top.range_m)} m`;
}

function renderAdvice(f) {
  const a = f.advice;
  if (!a) { $("advice").textContent = "-"; return; }
  const hd = a.preferred_heading_deg === null ? "-" : `${Math.round(a.preferred_heading_deg)}\u00b0`;
  const vs = a.preferred_vs_mps === null ? "-" : `${a.preferred_vs_mps.toFixed(1)} m/s`;
  $("advice").textContent = `advice: heading ${hd}, vertical speed ${vs}`;
}

$("play").addEventListener("click", () => {
  state.playing = !state.playing;
  send({ cmd: state.playing ? "play" : "pause" });
  $("play").textContent = state.playing ? "pause" : "play";
  if (state.playing) setStatus("live");
});
$("speed").addEventListener("change", () => send({ cmd: "speed", value: parseFloat($("speed").value) }));
$("seek").addEventListener("change", () => send({ cmd: "seek", index: parseInt($("seek").value, 10) }));
$("scale").addEventListener("change", () => { if (state.frame) drawPlan(state.frame); });

connect();
