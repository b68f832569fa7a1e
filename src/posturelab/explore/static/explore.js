// posturelab explore: sends the controls to POST api/views on every change and draws what
// comes back (Chart.js for the charts, plain SVG for the stick figure). The server does all
// of the physics; this file only reads controls and draws numbers.
"use strict";

const form = document.getElementById("controls-form");
const message = document.getElementById("message");
const LINK_COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"];
let requested = 0;   // number of the newest request sent
let timer = null;
let updates = 0;

// -- controls -----------------------------------------------------------------------------

function values() {
  const out = {};
  for (const el of form.querySelectorAll("input[name], select[name]")) {
    if (!el.disabled) out[el.name] = el.value;  // a greyed-out box is not used: not sent
  }
  return out;
}

for (const slider of form.querySelectorAll("input[type=range]")) {
  const box = document.getElementById(slider.dataset.for);
  slider.addEventListener("input", () => { box.value = slider.value; schedule(); });
  box.addEventListener("input", () => {
    const v = Number(box.value);
    if (box.value !== "" && Number.isFinite(v)) slider.value = String(v);
    schedule();
  });
}
// a controller's delay τ [s] and weight W [-] (posturelab.model.controllers), by name
const PRESETS = JSON.parse(document.getElementById("controller-presets").textContent);

function setBox(name, value) {
  document.getElementById(name).value = String(value);
  form.querySelector(`input[data-for="${name}"]`).value = String(value);
}

for (const select of form.querySelectorAll("select")) {
  select.addEventListener("change", () => {
    const preset = select.id === "controller" ? PRESETS[select.value] : undefined;
    if (preset) {  // the controller's own delay and weight, still editable
      setBox("feedback_delay", preset.feedback_delay);
      setBox("proprioceptive_weight", preset.proprioceptive_weight);
    }
    enableFields();
    schedule();
  });
}

function enableFields() {
  const body = document.getElementById("body").value;
  const controller = document.getElementById("controller").value;
  const ownGains = !(controller in PRESETS);
  const oneLink = body.endsWith("one link") || !ownGains;
  const bodyFree = body.startsWith("height");
  const tilt = ["tilt", "visual tilt"].includes(document.getElementById("perturbation").value);
  const fields = [["height", bodyFree], ["mass", bodyFree], ["step_speed", !tilt],
                  ["tilt_amplitude", tilt], ["tilt_frequency", tilt],
                  ["viscosity_ratio", ownGains]];
  for (const box of form.querySelectorAll("#group-pairs input[name], #group-active input[name]")) {
    if (box.name === "viscosity_ratio") continue;
    // own gains only; on one link only the ankle pair's
    fields.push([box.name, ownGains && (!oneLink || box.name.endsWith(":ankle"))]);
  }
  for (const [name, on] of fields) {
    const box = document.getElementById(name);
    box.disabled = !on;
    form.querySelector(`input[data-for="${name}"]`).disabled = !on;
    if (!on) { box.classList.remove("invalid"); box.removeAttribute("aria-invalid"); }
  }
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(update, 40);
}

// -- the round trip -----------------------------------------------------------------------

async function update() {
  const mine = ++requested;
  const started = performance.now();
  document.getElementById("timing").textContent = "computing…";
  let response, data;
  try {
    response = await fetch("api/views", {
      method: "POST", headers: {"Content-Type": "application/json"},
      body: JSON.stringify(values()),
    });
    data = await response.json();
  } catch (err) {
    if (mine === requested) showError("the posturelab server does not answer (" + err + ")");
    return;
  }
  if (mine !== requested) return;  // a newer change is on its way: draw that one
  if (!response.ok) {
    showError(data.error, data.field);
    document.getElementById("timing").textContent = "";
    return;
  }
  clearError();
  draw(data);
  const ms = performance.now() - started;
  updates += 1;
  document.body.dataset.updates = String(updates);
  document.body.dataset.roundTrip = ms.toFixed(1);
  document.getElementById("timing").textContent = `updated in ${ms.toFixed(0)} ms`;
}

function showError(text, field) {
  message.textContent = text;
  message.hidden = false;
  for (const el of form.querySelectorAll(".invalid")) el.classList.remove("invalid");
  const box = field ? document.getElementById(field) : null;
  if (box) { box.classList.add("invalid"); box.setAttribute("aria-invalid", "true"); }
}

function clearError() {
  message.hidden = true;
  message.textContent = "";
  for (const el of form.querySelectorAll(".invalid")) {
    el.classList.remove("invalid");
    el.removeAttribute("aria-invalid");
  }
}

// -- drawing ------------------------------------------------------------------------------

Chart.defaults.animation = false;
Chart.defaults.font.size = 11;
Chart.defaults.maintainAspectRatio = false;

function axis(title, type = "linear") {
  return {type, title: {display: true, text: title}};
}

const polesChart = new Chart(document.getElementById("poles-chart"), {
  type: "scatter",
  data: {datasets: [
    {label: "poles without delay", data: [], pointStyle: "crossRot", radius: 7,
     borderColor: "#1f77b4", borderWidth: 2},
    {label: "rightmost roots at τ", data: [], pointStyle: "circle", radius: 6,
     borderColor: "#d62728", backgroundColor: "rgba(0,0,0,0)", borderWidth: 1.5},
  ]},
  options: {scales: {x: axis("real part [1/s]"), y: axis("imaginary part [rad/s]")}},
});

const FREQUENCY_TICKS = [0.01, 0.03, 0.1, 0.3, 1, 3, 10];  // [Hz], the labelled ones
// the FRF's frequency axis: its whole range even when nothing is drawn, labels upright
function frequencyAxis() {
  return {...axis("frequency [Hz]", "logarithmic"), min: 0.01, max: 10,
          ticks: {maxRotation: 0, autoSkip: false,
                  callback: v => FREQUENCY_TICKS.some(f => Math.abs(v / f - 1) < 1e-6)
                    ? String(Number(v.toPrecision(1))) : ""}};
}

const frfGain = new Chart(document.getElementById("frf-gain"), {
  type: "scatter",
  data: {datasets: [{label: "gain [-]", data: [], showLine: true, pointRadius: 0,
                     borderColor: "#1f77b4"}]},
  options: {plugins: {legend: {display: false}},
            scales: {x: frequencyAxis(), y: axis("gain [-]", "logarithmic")}},
});

const frfPhase = new Chart(document.getElementById("frf-phase"), {
  type: "scatter",
  data: {datasets: [{label: "phase [deg]", data: [], showLine: true, pointRadius: 0,
                     borderColor: "#1f77b4"}]},
  options: {plugins: {legend: {display: false}},
            scales: {x: frequencyAxis(), y: axis("phase [deg]")}},
});

const responseChart = new Chart(document.getElementById("response-chart"), {
  type: "scatter",
  data: {datasets: []},
  options: {scales: {x: axis("time t [s]"), y: axis("link angle θ [rad]")}},
});

const phaseChart = new Chart(document.getElementById("phase-chart"), {
  type: "scatter",
  data: {datasets: [{label: "centre of gravity", data: [], showLine: true, pointRadius: 0,
                     borderColor: "#1f77b4"},
                    {label: "start", data: [], pointRadius: 5, backgroundColor: "#2ca02c"}]},
  options: {scales: {x: axis("CoG position x_c from the ankle [m]"),
                     y: axis("CoG velocity ẋ_c [m/s]")}},
});

function points(xs, ys) {
  const out = new Array(xs.length);
  for (let i = 0; i < xs.length; i++) out[i] = {x: xs[i], y: ys[i]};
  return out;
}

function complexText(z) {
  const sign = z.im < 0 ? "−" : "+";
  return `${z.re.toFixed(3)} ${sign} ${Math.abs(z.im).toFixed(3)}j`;
}

function draw(d) {
  const verdict = document.getElementById("verdict");
  verdict.textContent = d.verdict;
  verdict.className = d.stable ? "stable" : d.verdict.startsWith("marginal") ? "marginal"
    : "unstable";
  document.getElementById("delay-margin").textContent = d.delay_margin_note ? d.delay_margin_note
    : !d.stable_without_delay ? "none (unstable without delay)"
      : d.delay_margin === null ? "∞ (no crossing)" : `${d.delay_margin.toPrecision(3)} s`;
  document.getElementById("delay-note").textContent =
    d.delayed_part === "active" ? "(of the active gains)" : "(of the whole pair feedback)";
  const outcome = document.getElementById("outcome");
  outcome.textContent = d.run.outcome;
  outcome.title = d.run.message;

  polesChart.data.datasets[0].data = d.poles.map(z => ({x: z.re, y: z.im}));
  polesChart.data.datasets[1].data = d.roots.map(z => ({x: z.re, y: z.im}));
  polesChart.update();
  const body = document.querySelector("#poles tbody");
  body.replaceChildren();
  const rows = Math.max(d.poles.length, d.roots.length);
  for (let i = 0; i < rows; i++) {
    const tr = document.createElement("tr");
    for (const z of [d.poles[i], d.roots[i]]) {
      const td = document.createElement("td");
      if (z) { td.textContent = complexText(z); td.dataset.re = z.re; td.dataset.im = z.im; }
      tr.appendChild(td);
    }
    tr.children[0].classList.add("pole");
    tr.children[1].classList.add("root");
    body.appendChild(tr);
  }

  const frfNote = document.getElementById("frf-note");
  frfNote.textContent = d.frf.note || "";
  frfNote.hidden = !d.frf.note;
  frfGain.data.datasets[0].data = points(d.frf.frequency, d.frf.gain);
  frfGain.update();
  frfPhase.data.datasets[0].data = points(d.frf.frequency, d.frf.phase);
  frfPhase.update();

  responseChart.data.datasets = d.run.theta.map((series, i) => ({
    label: `θ${i + 1} (${d.run.link_names[i]})`, data: points(d.run.time, series),
    showLine: true, pointRadius: 0, borderColor: LINK_COLORS[i % LINK_COLORS.length],
    borderWidth: 1.5,
  }));
  responseChart.update();
  phaseChart.data.datasets[0].data = points(d.run.cog_x, d.run.cog_v);
  phaseChart.data.datasets[1].data = [{x: d.run.cog_x[0], y: d.run.cog_v[0]}];
  phaseChart.update();
  startStick(d.run);
}

// -- the stick figure ---------------------------------------------------------------------

let stick = null;

function startStick(run) {
  const scale = 1.8 / Math.max(run.height, 1e-6);  // the upright body fills the view
  stick = {run, scale, started: performance.now()};
  const joints = document.getElementById("joints");
  joints.replaceChildren();
  for (let i = 0; i < run.frames[0].length; i++) {
    const c = document.createElementNS("http://www.w3.org/2000/svg", "circle");
    c.setAttribute("r", "0.03");
    c.setAttribute("fill", LINK_COLORS[Math.max(0, i - 1) % LINK_COLORS.length]);
    joints.appendChild(c);
  }
}

function stickFrame(now) {
  if (stick) {
    const {run, scale} = stick;
    const n = run.frames.length;
    const elapsed = Math.max(0, now - stick.started) / 1000;  // (a frame's time may be earlier)
    const k = Math.floor(elapsed * run.frame_rate) % (n + 10);
    const frame = run.frames[Math.min(k, n - 1)];  // hold the last frame a moment
    const alpha = run.surface_tilt[Math.min(k, n - 1)];  // [rad], positive toes-up (+x up)
    const platform = document.getElementById("platform");
    platform.setAttribute("x1", (-1.1 * Math.cos(alpha)).toFixed(4));
    platform.setAttribute("y1", (-1.1 * Math.sin(alpha)).toFixed(4));
    platform.setAttribute("x2", (1.1 * Math.cos(alpha)).toFixed(4));
    platform.setAttribute("y2", (1.1 * Math.sin(alpha)).toFixed(4));
    document.getElementById("chain").setAttribute(
      "points", frame.map(p => `${(p[0] * scale).toFixed(4)},${(p[1] * scale).toFixed(4)}`).join(" "));
    const circles = document.getElementById("joints").children;
    for (let i = 0; i < circles.length; i++) {
      circles[i].setAttribute("cx", (frame[i][0] * scale).toFixed(4));
      circles[i].setAttribute("cy", (frame[i][1] * scale).toFixed(4));
    }
    document.getElementById("stick-time").textContent =
      `t = ${(Math.min(k, n - 1) / run.frame_rate).toFixed(2)} s`;
  }
  requestAnimationFrame(stickFrame);
}

enableFields();
requestAnimationFrame(stickFrame);
update();
