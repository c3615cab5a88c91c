// polydyn report: draws the charts (Apache ECharts, inlined above) from the JSON specifications the
// generator wrote into #pd-charts as they come into view, and mounts the 3-D replays (their data
// loaded on demand) when a viewer bundle is inlined.
(function () {
  'use strict';
  // a number for axis labels and tooltips: 3 significant digits, scientific outside [1e-3, 1e5)
  function num(x) {
    if (typeof x !== 'number' || !isFinite(x)) return String(x);
    if (x === 0) return '0';
    var a = Math.abs(x);
    if (a >= 1e-3 && a < 1e5) return String(Number(x.toPrecision(3)));
    var p = x.toExponential(2).split('e');
    return p[0].replace(/\.?0+$/, '') + 'e' + Number(p[1]);
  }
  // log axes: powers of ten as 1e-3, others as numbers
  function sci(x) {
    var l = Math.log10(Math.abs(x));
    return Math.abs(l - Math.round(l)) < 1e-9 && (x < 1e-2 || x >= 1e4) ? '1e' + Math.round(l) : num(x);
  }
  var FORMATTERS = {
    num: num,
    sci: sci,
    deg: function (x) { return x + '°'; },
    // tooltip of a point [x, y, label]
    point3: function (p) {
      var d = p.data || p.value;
      return p.marker + p.seriesName + (d[2] !== undefined ? ' · ' + d[2] : '') + '<br>' + num(d[0]) + ', ' + num(d[1]);
    },
    // tooltip of a polar point [radius, angle]
    polar: function (p) {
      var d = p.data || p.value;
      return p.marker + p.seriesName + '<br>' + num(d[1]) + '°: ' + num(d[0]);
    }
  };
  // replaces formatter names by the functions above
  function decorate(o) {
    if (Array.isArray(o)) return o.map(decorate);
    if (o && typeof o === 'object') {
      var out = {};
      for (var k in o) {
        var v = o[k];
        if ((k === 'formatter' || k === 'valueFormatter') && typeof v === 'string' && FORMATTERS[v]) out[k] = FORMATTERS[v];
        else out[k] = decorate(v);
      }
      return out;
    }
    return o;
  }
  // Each chart is drawn when it comes near the screen (a report has tens of charts, which would take
  // about a second to draw at once); all of them before printing.
  var specs = JSON.parse(document.getElementById('pd-charts').textContent);
  var charts = [];
  var specById = {};
  specs.forEach(function (s) { specById[s.id] = s; });
  // a chart with alternatives (e.g. one per body) shows the one its select chose (s.current)
  function optionOf(s) {
    var option = decorate(s.alternatives ? s.alternatives[s.current || 0] : s.option);
    option.animation = false;
    option.textStyle = { fontFamily: 'system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif' };
    return option;
  }
  function draw(s) {
    if (s.drawn) return;
    s.drawn = true;
    var chart = echarts.init(document.getElementById(s.id), null, { renderer: 'svg' });
    chart.setOption(optionOf(s));
    s.chart = chart;
    charts.push(chart);
  }
  Array.prototype.forEach.call(document.querySelectorAll('select.pd-alt'), function (select) {
    select.addEventListener('change', function () {
      select.dataset.charts.split(' ').forEach(function (id) {
        var s = specById[id];
        if (!s) return;
        s.current = Number(select.value);
        if (s.chart) s.chart.setOption(optionOf(s), true);
      });
    });
  });
  function drawAll() { specs.forEach(draw); }
  if (typeof IntersectionObserver === 'function') {
    var specOf = {};
    var near = new IntersectionObserver(function (entries) {
      entries.forEach(function (e) {
        if (!e.isIntersecting) return;
        near.unobserve(e.target);
        draw(specOf[e.target.id]);
      });
    }, { rootMargin: '800px 0px' });
    specs.forEach(function (s) {
      specOf[s.id] = s;
      near.observe(document.getElementById(s.id));
    });
  } else {
    drawAll();
  }
  window.addEventListener('beforeprint', drawAll);
  window.addEventListener('resize', function () { charts.forEach(function (c) { c.resize(); }); });
  window.polydynReport = { charts: charts, drawAll: drawAll, specs: specs };

  // a link of class pd-seek (data-t, data-body) into a block holding a replay: opens it, and once mounted
  // shows time t with that body selected
  function seek(d, at) {
    d.pdSeek = at;
    var replay = d.pdReplay;
    if (!replay) return;
    if (replay.playing && typeof replay.pause === 'function') replay.pause();
    replay.setTime(at.t);
    var bodies = replay.runs && replay.runs[0] ? replay.runs[0].bodies : [];
    for (var i = 0; i < bodies.length; ++i) if (bodies[i].name === at.body) replay.selectBody(i);
    if (typeof replay.renderNow === 'function') replay.renderNow();
  }
  document.addEventListener('click', function (e) {
    var a = e.target.closest ? e.target.closest('a.pd-seek') : null;
    if (!a) return;
    var holder = document.querySelector(a.getAttribute('href'));
    var d = holder && holder.querySelector('details.replay');
    if (!d) return;
    seek(d, { t: Number(a.dataset.t), body: a.dataset.body });
    d.open = true;
  });

  // replays: the inlined viewer bundle defines PolydynViewer.mount(element, files); each replay's
  // files are in a script of the folder beside the page (body's data-replays), which calls
  // polydynReplay(NAME, files). It is added when the replay's <details> is first opened: a script
  // loads from file:// where fetch() does not. One WebGL context per open replay.
  var viewer = window.PolydynViewer;
  var folder = document.body.dataset.replays;
  var waiting = {};  // file name → mounts its files
  window.polydynReplay = function (name, files) {
    var mount = waiting[name];
    delete waiting[name];
    if (mount) mount(files);
  };
  Array.prototype.forEach.call(document.querySelectorAll('details.replay'), function (d) {
    d.addEventListener('toggle', function () {
      if (!d.open || d.dataset.mounted) return;
      d.dataset.mounted = '1';
      var target = d.querySelector('.pd-replay');
      if (!viewer || typeof viewer.mount !== 'function') {
        target.textContent = 'The inlined viewer bundle does not define PolydynViewer.mount.';
        return;
      }
      var name = d.dataset.replay, src = folder + '/' + name;
      var missing = 'The replay data is missing: this page loads it from ' + src + ', which is not there. polydyn report writes ' +
        'the folder ' + folder + '/ beside the page; keep it there (copy both together).';
      target.textContent = 'Loading the replay data from ' + src + ' …';
      waiting[name] = function (files) {
        target.textContent = '';
        d.pdReplay = viewer.mount(target, files);
        if (d.pdSeek) seek(d, d.pdSeek);
      };
      var script = document.createElement('script');
      script.src = encodeURIComponent(folder) + '/' + encodeURIComponent(name);
      function fail(message) {
        delete waiting[name];
        target.textContent = message;
        target.classList.add('pd-missing');
      }
      script.onerror = function () { fail(missing); };
      script.onload = function () {
        if (waiting[name]) fail(src + ' does not hold the replay data (it does not call polydynReplay for ' + name + ').');
      };
      document.head.appendChild(script);
    });
  });
})();
