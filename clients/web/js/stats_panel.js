// The server's `stats`, asked for once a second: rendered frames per second, clients, LUT
// rebuild progress, and GPU milliseconds per pass drawn as stacked bars over the last minute.

const $ = (id) => document.getElementById(id);
const HISTORY = 60;
const COLOURS = ["#4fc3f7", "#ffb74d", "#81c784", "#e57373", "#ba68c8", "#fff176", "#90a4ae",
                 "#f06292"];

export class StatsPanel {
  constructor() {
    this.plot = $("pass-plot");
    this.context = this.plot.getContext("2d");
    this.history = [];
    this.colours = new Map();
  }

  colour(name) {
    if (!this.colours.has(name))
      this.colours.set(name, COLOURS[this.colours.size % COLOURS.length]);
    return this.colours.get(name);
  }

  update(stats) {
    $("server-fps").textContent = Number(stats.fps).toFixed(1);
    $("clients").textContent = String(stats.clients);
    const progress = Number(stats.lut_rebuild_progress);
    $("lut-progress").value = progress;
    $("lut-progress-text").textContent = progress >= 1 ? "idle" : `${Math.round(progress * 100)} %`;
    const passes = stats.passes && typeof stats.passes === "object" ? stats.passes : {};
    this.history.push(passes);
    if (this.history.length > HISTORY) this.history.shift();
    this.drawPlot();
    this.drawLegend(passes);
  }

  drawPlot() {
    const { width, height } = this.plot;
    const ctx = this.context;
    ctx.clearRect(0, 0, width, height);
    const totals = this.history.map((p) => Object.values(p).reduce((a, b) => a + b, 0));
    // The scale follows the 90th percentile so that one slow frame (the first) does not
    // flatten the rest; taller bars are clipped.
    const sorted = [...totals].sort((a, b) => a - b);
    const top = Math.max(1, sorted[Math.floor((sorted.length - 1) * 0.9)] || 0) * 1.2;
    const barWidth = width / HISTORY;
    this.history.forEach((passes, i) => {
      let y = height;
      for (const [name, ms] of Object.entries(passes)) {
        const h = (ms / top) * (height - 12);
        ctx.fillStyle = this.colour(name);
        ctx.fillRect(i * barWidth, y - h, Math.max(1, barWidth - 1), h);
        y -= h;
      }
    });
    ctx.fillStyle = "#8a96a3";
    ctx.font = "10px system-ui, sans-serif";
    ctx.fillText(`${top.toFixed(1)} ms`, 2, 10);
  }

  drawLegend(passes) {
    const legend = $("pass-legend");
    legend.replaceChildren(...Object.entries(passes).map(([name, ms]) => {
      const item = document.createElement("li");
      const swatch = document.createElement("span");
      swatch.className = "swatch";
      swatch.style.background = this.colour(name);
      item.append(swatch, `${name} ${ms.toFixed(2)} ms`);
      return item;
    }));
  }
}
