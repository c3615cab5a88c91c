// Chart options shared by the sections (plain JSON for ECharts: formatter names stand for page.js functions).

// A log–log diagram of error (or error/tolerance) against cost, one line per series, with an optional dashed
// horizontal guide (a target error, a tolerance) carried by the first series — a series of its own would enter
// the legend, and ECharts draws no {yAxis} mark line on a log axis.
export function logLogOption({ xName, yName, series, guide = null, right = 90 }) {
  const xs = series.flatMap((s) => s.data.map((d) => d[0]));
  if (guide && series.length && xs.length) {
    series[0].markLine = { silent: true, symbol: 'none', lineStyle: { color: '#555', type: 'dashed', width: 1.2 },
      label: { formatter: guide.label, position: 'end', color: '#555' },
      data: [[{ coord: [Math.min(...xs), guide.value] }, { coord: [Math.max(...xs), guide.value] }]] };
  }
  return {
    tooltip: { trigger: 'item', formatter: 'point3' },
    legend: { top: 0 },
    grid: { left: 70, right, top: 55, bottom: 55 },
    xAxis: { type: 'log', name: xName, nameLocation: 'middle', nameGap: 32, axisLabel: { formatter: 'sci' } },
    yAxis: { type: 'log', name: yName, nameLocation: 'middle', nameGap: 50, axisLabel: { formatter: 'sci' } },
    series,
  };
}

// One line series of a log–log diagram: points [x, y, label], the engine-variant's colour.
// lineType: 'solid', 'dashed' or 'dotted'.
export function logLogLine(name, color, data, lineType = 'solid') {
  return { name, type: 'line', symbolSize: 7, lineStyle: { color, width: 2, type: lineType }, itemStyle: { color }, data };
}
