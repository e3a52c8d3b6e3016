// Time plots of the page (docs/view.md): the last WINDOW_S seconds of message stamps, drawn
// with uPlot. Each line names the scale (axis) it is read on, so that millimetres of x and y
// are not flattened by z's metre or an error in degrees by one in millimetres: the first
// scale is the left axis, a second one the right axis.
import uPlot from 'uplot';

export const WINDOW_S = 10;

/// Samples (stamp in seconds, one value per line) over the last WINDOW_S seconds.
export class Series {
  constructor() {
    this.t = [];
    this.v = [];
    this.changed = false;
  }
  push(t, values) {
    this.t.push(t);
    this.v.push(values);
    const start = t - WINDOW_S;
    let k = 0;
    while (k < this.t.length && this.t[k] < start) k++;
    if (k > 0) {
      this.t.splice(0, k);
      this.v.splice(0, k);
    }
    this.changed = true;
  }
  clear() {
    this.t = [];
    this.v = [];
    this.changed = true;
  }
}

const fixed = (digits) => (u, v) => (v == null ? '-' : v.toFixed(digits));

export class TimePlot {
  /// lines: [{label, color, scale}]; scales: {name: axis label}, in axis order (left, right).
  constructor(element, series, lines, scales, {width = 480, height = 190} = {}) {
    this.series = series;
    this.lines = lines;
    const scaleNames = Object.keys(scales);
    const font = {font: '11px sans-serif', labelFont: 'bold 11px sans-serif', labelSize: 16};
    const axes = [{label: 'stamp - newest (s)', size: 30, ...font}];
    scaleNames.forEach((name, i) => {
      const axis = {scale: name, label: scales[name], size: 62, ...font};
      if (i > 0) Object.assign(axis, {side: 1, grid: {show: false}});
      axes.push(axis);
    });
    const uScales = {x: {time: false, range: [-WINDOW_S, 0]}};
    for (const name of scaleNames) uScales[name] = {auto: true};
    this.plot = new uPlot(
        {
          width,
          height,
          scales: uScales,
          axes,
          cursor: {show: true, drag: {x: false, y: false}},
          legend: {live: false},
          series: [
            {label: 't (s)', value: fixed(3)},
            ...lines.map((l) => ({
                           label: l.label,
                           stroke: l.color,
                           scale: l.scale,
                           width: 1.5,
                           value: fixed(2),
                           points: {show: false}
                         })),
          ],
        },
        this.empty(), element);
  }

  empty() { return [[], ...this.lines.map(() => [])]; }

  /// Redraws if the series changed since the last call.
  update() {
    if (!this.series.changed) return;
    this.series.changed = false;
    const {t, v} = this.series;
    const newest = t.length ? t[t.length - 1] : 0;
    const data = [t.map((s) => s - newest)];
    this.lines.forEach((_, j) => data.push(v.map((values) => values[j])));
    this.plot.setData(data);
  }
}
