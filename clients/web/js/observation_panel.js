// A METAR or SPECI report applied to the weather (apply_observation) and what the server decoded
// it to: station and time, cloud layers, visibility, wind, temperature and dew point, and the
// groups the world could not place. The decoded report shows while weather.source is "metar"
// (another source, a preset or a forecast, hides it); the server's refusal shows beside the
// button.

import { clearErrors, showReplyError } from "./field_errors.js";

const $ = (id) => document.getElementById(id);
const pad = (n) => String(n).padStart(2, "0");

// [label, text] rows for a decoded report (PROTOCOL.md, "METAR decoding").
export function describeReport(report) {
  const rows = [];
  const time = report.observed
    ? `day ${report.observed.day}, ${pad(report.observed.hour)}:${pad(report.observed.minute)} UTC`
    : "not given";
  rows.push(["Station", `${report.station} (${report.type}${report.auto ? ", automatic" : ""})`]);
  rows.push(["Observed", time]);
  let layers = (report.clouds || []).map((c) => {
    const base = c.base_m === null ? "base ?" : `${Math.round(c.base_m)} m`;
    const kind = c.cumulonimbus ? " CB" : c.towering_cumulus ? " TCU" : "";
    return `${c.amount} ${base}${kind}`;
  }).join(", ");
  if (report.vertical_visibility_m !== null && report.vertical_visibility_m !== undefined)
    layers = `sky obscured, vertical visibility ${Math.round(report.vertical_visibility_m)} m`;
  else if (!layers) layers = report.sky === "not_reported" ? "not reported" : report.sky;
  rows.push(["Clouds", layers]);
  const v = report.visibility;
  rows.push(["Visibility", v ? `${v.bound === "at_least" ? "≥ " : v.bound === "less_than"
    ? "< " : ""}${v.metres >= 1000 ? `${(v.metres / 1000).toFixed(1)} km` : `${v.metres} m`}`
    : "not reported"]);
  const w = report.wind;
  let wind = "not reported";
  if (w && w.calm) wind = "calm";
  else if (w) {
    const from = w.direction_deg === null ? "variable" : `from ${w.direction_deg}°`;
    const speed = w.speed_m_s === null ? "?" : `${w.speed_m_s.toFixed(1)} m/s`;
    wind = `${from}, ${speed}${w.gust_m_s ? `, gusts ${w.gust_m_s.toFixed(1)} m/s` : ""}`;
  }
  rows.push(["Wind", wind]);
  const t = report.temperature_c, td = report.dew_point_c;
  rows.push(["T / Td", `${t === null ? "?" : `${t} °C`} / ${td === null ? "?" : `${td} °C`}` +
             (report.relative_humidity === null ? ""
               : ` (RH ${Math.round(report.relative_humidity * 100)} %)`)]);
  const weather = report.weather && report.weather.groups.length
    ? report.weather.groups.join(" ") : "none";
  rows.push(["Weather", weather]);
  return rows;
}

export class ObservationPanel {
  constructor(request, onRevision) {
    this.request = request;
    this.onRevision = onRevision;
    this.report = null; // the last report this page applied
    $("metar-apply").addEventListener("click", () => this.send());
  }

  async send() {
    const metar = $("metar-text").value.trim();
    const reply = await this.request({ type: "apply_observation", metar });
    if (reply.type !== "observation") {
      showReplyError(reply, "metar");
      return;
    }
    clearErrors(["metar"]);
    this.onRevision(reply.revision);
    $("metar-status").textContent = `applied: revision ${reply.revision}`;
    this.show(reply.report, reply.unmapped || []);
    this.update({ weather: { source: "metar" } });
  }

  show(report, unmapped) {
    this.report = report;
    const table = $("metar-report");
    table.replaceChildren();
    const rows = describeReport(report);
    for (const u of unmapped)
      rows.push(["Unmapped", `${u.group}${u.etage ? ` (${u.etage})` : ""}: ${u.reason}`]);
    for (const [label, text] of rows) {
      const tr = document.createElement("tr");
      const th = document.createElement("th");
      const td = document.createElement("td");
      th.textContent = label;
      td.textContent = text;
      tr.append(th, td);
      table.append(tr);
    }
  }

  // The decoded report is shown while the weather is the observation's.
  update(state) {
    const metar = Boolean(state && state.weather && state.weather.source === "metar");
    $("metar-report").hidden = !(metar && this.report);
    $("metar-source").textContent = state && state.weather ? state.weather.source : "";
  }
}
