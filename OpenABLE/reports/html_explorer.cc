#include "OpenABLE/reports/html_explorer.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <opencv2/imgproc.hpp>
#include <tuple>
#include <vector>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/image_codec.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/reports/html_text.h"

namespace openable {
namespace {

constexpr int kSheetColumns = 32;  // thumbnails across a sheet
constexpr int kSheetRows = 32;     // and down: at most 1024 frames per JPEG
constexpr int kThumbQuality = 80;
constexpr int kMatrixDisplay = 600;  // CSS pixels of the matrix's longer side on the page

const cv::Vec3b kTruthTint(255, 128, 0);  // as the overlay figure's (BGR)

// A frame as 8-bit grey or BGR (the grey image of a stereo pair with its disparity).
cv::Mat EightBit(const cv::Mat& frame) {
  cv::Mat image = frame;
  if (image.channels() == 2) {
    cv::Mat first;
    cv::extractChannel(image, first, 0);
    image = first;
  } else if (image.channels() == 4) {
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    image = bgr;
  }
  if (image.depth() != CV_8U) image.convertTo(image, CV_8U, 255.0);
  return image;
}

// The frames of rows (or columns) [first, first + count) of the full matrix, as thumbnails on
// JPEG sheets of kSheetColumns x kSheetRows cells.
struct FrameSet {
  bool row = true;
  int first = 0, count = 0;
  int cell_width = 0, cell_height = 0;
  std::vector<std::string> names;
  std::vector<std::string> sheets;  // JPEG bytes
};

std::string FrameName(const ReportFrames& frames, bool row, int index) {
  if (frames.name) return frames.name(row, index);
  return std::string(row ? "row " : "column ") + std::to_string(index);
}

// Fills the names and, when the frames can be read, the sheets of `set`, each thumbnail at most
// `max_pixels` pixels; `read_one` is called after each frame read.
void MakeSheets(const ReportFrames& frames, double max_pixels, FrameSet& set,
                const std::function<void()>& read_one) {
  for (int i = 0; i < set.count; ++i)
    set.names.push_back(FrameName(frames, set.row, set.first + i));
  if (!frames.read || set.count == 0) return;
  // The cell: the first frame's shape, at most kExploreThumbHeight high and kExploreThumbWidth
  // across, smaller when the report's budget asks.
  const cv::Mat first = EightBit(frames.read(set.row, set.first));
  read_one();
  double scale = std::min(
      {1.0, double(kExploreThumbHeight) / first.rows, double(kExploreThumbWidth) / first.cols});
  if (first.rows * first.cols * scale * scale > max_pixels)
    scale = std::sqrt(max_pixels / (double(first.rows) * first.cols));
  set.cell_width = std::max(4, static_cast<int>(std::lround(first.cols * scale)));
  set.cell_height = std::max(4, static_cast<int>(std::lround(first.rows * scale)));
  const bool colour = first.channels() == 3;
  const int per_sheet = kSheetColumns * kSheetRows;
  for (int start = 0; start < set.count; start += per_sheet) {
    const int n = std::min(per_sheet, set.count - start);
    const int columns = std::min(kSheetColumns, n);
    const int rows = (n + kSheetColumns - 1) / kSheetColumns;
    cv::Mat sheet(rows * set.cell_height, columns * set.cell_width, colour ? CV_8UC3 : CV_8UC1,
                  cv::Scalar::all(128));
    for (int k = 0; k < n; ++k) {
      cv::Mat image = first;
      if (start + k > 0) {
        image = EightBit(frames.read(set.row, set.first + start + k));
        read_one();
      }
      if (image.channels() == 3 && !colour) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
      if (image.channels() == 1 && colour) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
      // Fitted into the cell, centred (frames of another shape are letterboxed).
      const double s =
          std::min(double(set.cell_width) / image.cols, double(set.cell_height) / image.rows);
      const int w =
          std::max(1, std::min(set.cell_width, static_cast<int>(std::lround(image.cols * s))));
      const int h =
          std::max(1, std::min(set.cell_height, static_cast<int>(std::lround(image.rows * s))));
      cv::Mat fitted;
      cv::resize(image, fitted, cv::Size(w, h), 0, 0, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
      const int x = (k % kSheetColumns) * set.cell_width + (set.cell_width - w) / 2;
      const int y = (k / kSheetColumns) * set.cell_height + (set.cell_height - h) / 2;
      fitted.copyTo(sheet(cv::Rect(x, y, w, h)));
    }
    set.sheets.push_back(EncodeJpegFile(sheet, kThumbQuality));
  }
}

// The block in grey (dark = small distance, no value white) with the ground truth tinted (when
// given), at most kExploreImageSide pixels a side: larger blocks are averaged down
// (INTER_AREA), and a pixel is tinted when any of its cells is a true pair.
cv::Mat3b MatrixImage(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                      const GroundTruth* truth) {
  const int rows = layout.queries, cols = layout.references;
  cv::Mat1f block = matrix(cv::Rect(layout.col_offset, layout.row_offset, cols, rows)).clone();
  for (int q = 0; q < rows; ++q) {
    float* p = block.ptr<float>(q);
    for (int c = 0; c < cols; ++c) p[c] = std::isfinite(p[c]) ? std::clamp(p[c], 0.0f, 1.0f) : 1.0f;
  }
  cv::Mat1f mask(rows, cols, 0.0f);
  const int truth_rows = truth ? std::min(rows, static_cast<int>(truth->matches.size())) : 0;
  for (int q = 0; q < truth_rows; ++q)
    for (const int c : truth->matches[q])
      if (c >= 0 && c < cols) mask(q, c) = 1.0f;
  const int side = std::max(rows, cols);
  if (side > kExploreImageSide) {
    const double s = double(kExploreImageSide) / side;
    const cv::Size size(std::max(1, static_cast<int>(std::lround(cols * s))),
                        std::max(1, static_cast<int>(std::lround(rows * s))));
    cv::resize(block, block, size, 0, 0, cv::INTER_AREA);
    cv::resize(mask, mask, size, 0, 0, cv::INTER_AREA);
  }
  cv::Mat3b image(block.rows, block.cols);
  for (int y = 0; y < block.rows; ++y)
    for (int x = 0; x < block.cols; ++x) {
      const auto g = static_cast<std::uint8_t>(std::lround(255.0f * block(y, x)));
      cv::Vec3b p(g, g, g);
      if (mask(y, x) > 0)
        for (int ch = 0; ch < 3; ++ch)
          p[ch] = static_cast<std::uint8_t>((p[ch] + kTruthTint[ch] + 1) / 2);
      image(y, x) = p;
    }
  return image;
}

std::string Digits(const std::vector<std::uint8_t>& flags, std::size_t n) {
  std::string s(n, '0');
  for (std::size_t i = 0; i < n && i < flags.size(); ++i)
    if (flags[i]) s[i] = '1';
  return s;
}

// The script of the explorer (docs/output_formats.md, "HTML report"). Plain JavaScript, run
// once the page has loaded (the thumbnail sheets must be decoded to be drawn).
const char kScript[] = R"js(
window.addEventListener('load', function () {
  'use strict';
  function byId(id) { return document.getElementById(id); }
  function make(tag, cls, text) {
    var e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text !== undefined) e.textContent = text;
    return e;
  }
  function num(v, digits) {
    return v === null || v === undefined || !isFinite(v) ? '\u2013' : Number(v).toPrecision(digits);
  }
  function fixed(v, decimals) {
    return v === null || v === undefined || !isFinite(v) ? '\u2013' : Number(v).toFixed(decimals);
  }
  if (!byId('explore-frames')) return;
  var sets = JSON.parse(byId('explore-frames').textContent);
  // A canvas with frame `index` (of the full matrix) of frame set `s`; null without sheets.
  function thumbnail(s, index, cls) {
    var set = sets[s], k = index - set.first;
    if (!set.sheets.length || k < 0 || k >= set.count) return null;
    var per = set.columns * set.rows, sheet = byId(set.sheets[Math.floor(k / per)]);
    var j = k % per, w = set.cell[0], h = set.cell[1];
    var c = make('canvas', cls);
    c.width = w;
    c.height = h;
    c.getContext('2d').drawImage(sheet, (j % set.columns) * w, Math.floor(j / set.columns) * h,
                                 w, h, 0, 0, w, h);
    return c;
  }
  function frameName(s, index) { return sets[s].names[index - sets[s].first]; }

  function Explorer(root) {
    var run = JSON.parse(byId(root.getAttribute('data-data')).textContent);
    var Q = run.queries, R = run.references;
    var codes = (function () {
      var text = atob(byId(root.getAttribute('data-values')).textContent.trim());
      var a = new Uint8Array(text.length);
      for (var i = 0; i < text.length; ++i) a[i] = text.charCodeAt(i);
      return a;
    })();
    var image = root.querySelector('.ex-image'), overlay = root.querySelector('.ex-overlay');
    var slider = root.querySelector('.ex-threshold');
    var maxScore = 0, answered = [];
    for (var q = 0; q < Q; ++q) {
      if (run.best[q] < 0) continue;
      answered.push(q);
      if (run.score[q] > maxScore) maxScore = run.score[q];
    }
    slider.min = 0;
    slider.max = maxScore > 0 ? maxScore : 1;
    slider.step = 'any';
    // The run's operating point; without a threshold (no ground truth, no Match_threshold),
    // every answer.
    function start() {
      return run.threshold === null || run.threshold < 0 ? slider.max
                                                        : Math.min(run.threshold, slider.max);
    }
    slider.value = start();
    var pinned = null, shown = null;
    // Without ground truth nothing is right or wrong: no precision, recall or curve.
    var truth = run.truth;

    function threshold() { return parseFloat(slider.value); }
    function accepted(q, t) { return run.best[q] >= 0 && run.score[q] <= t; }
    function correct(q) { return run.correct.charAt(q) === '1'; }
    // Accepted by the run itself (Match_threshold, and Match_consistency's confirmation).
    function runAccepted(q) { return run.accepted.charAt(q) === '1'; }

    // Accepted answers at t, their precision (1 when none, as the evaluation counts it) and
    // recall (over the positive queries).
    function stats(t) {
      var n = 0, tp = 0;
      for (var i = 0; i < answered.length; ++i)
        if (run.score[answered[i]] <= t) { ++n; if (correct(answered[i])) ++tp; }
      return {accepted: n, tp: tp, precision: n ? tp / n : 1,
              recall: run.positive_queries ? tp / run.positive_queries : 0};
    }

    // Precision-recall curve (per query, from the run's curve) with a marker at the threshold.
    var pr = root.querySelector('.ex-pr'), marker = null;
    var W = 300, H = 240, L = 44, T = 12, PW = W - L - 12, PH = H - T - 36;
    function px(r) { return L + r * PW; }
    function py(p) { return T + (1 - p) * PH; }
    if (truth) {
      // Written as markup: the HTML parser puts <svg> in its namespace (no namespace URL in the
      // page, which holds no address at all).
      var m = ['<svg width="' + W + '" height="' + H + '" viewBox="0 0 ' + W + ' ' + H +
               '" role="img" aria-label="precision-recall curve">'];
      for (var g = 0; g <= 10; ++g) {
        var v = g / 10, colour = g % 5 === 0 ? '#bbb' : '#eee';
        m.push('<line x1="' + px(v) + '" x2="' + px(v) + '" y1="' + py(0) + '" y2="' + py(1) +
               '" stroke="' + colour + '"/><line x1="' + px(0) + '" x2="' + px(1) + '" y1="' +
               py(v) + '" y2="' + py(v) + '" stroke="' + colour + '"/>');
        if (g % 5 === 0)
          m.push('<text x="' + px(v) + '" y="' + (py(0) + 14) + '" text-anchor="middle" ' +
                 'font-size="11">' + v + '</text><text x="' + (px(0) - 5) + '" y="' + (py(v) + 4) +
                 '" text-anchor="end" font-size="11">' + v + '</text>');
      }
      m.push('<text x="' + px(0.5) + '" y="' + (H - 4) + '" text-anchor="middle" font-size="12">' +
             'recall</text><text x="12" y="' + py(0.5) + '" text-anchor="middle" font-size="12" ' +
             'transform="rotate(-90 12 ' + py(0.5) + ')">precision</text>');
      var points = [];
      for (var k = 0; k < run.curve.length; ++k) {
        var c = run.curve[k], n = c[1] + c[2];
        points.push(px(run.positive_queries ? c[1] / run.positive_queries : 0).toFixed(1) + ',' +
                    py(n ? c[1] / n : 1).toFixed(1));
      }
      m.push('<polyline points="' + points.join(' ') + '" fill="none" stroke="#1f5fbf" ' +
             'stroke-width="1.5"/><circle class="ex-marker" r="5" fill="#e07000" stroke="#000"/>' +
             '</svg>');
      pr.innerHTML = m.join('');
      marker = pr.querySelector('.ex-marker');
    } else {
      pr.hidden = true;
    }

    function drawOverlay() {
      var rect = image.getBoundingClientRect(), ratio = window.devicePixelRatio || 1;
      overlay.width = Math.max(1, Math.round(rect.width * ratio));
      overlay.height = Math.max(1, Math.round(rect.height * ratio));
      var ctx = overlay.getContext('2d'), sx = overlay.width / R, sy = overlay.height / Q;
      var mw = Math.max(3 * ratio, sx), mh = Math.max(3 * ratio, sy), t = threshold();
      ctx.clearRect(0, 0, overlay.width, overlay.height);
      // With ground truth green when right, red when wrong (drawn last: never hidden by a
      // neighbour); without, one colour.
      for (var pass = truth ? 0 : 2; pass < (truth ? 2 : 3); ++pass) {
        ctx.fillStyle = ['#00c800', '#e00000', '#ff8c00'][pass];
        for (var i = 0; i < answered.length; ++i) {
          var q = answered[i];
          if (run.score[q] > t || (pass < 2 && correct(q) !== (pass === 0))) continue;
          ctx.fillRect((run.best[q] + 0.5) * sx - mw / 2, (q + 0.5) * sy - mh / 2, mw, mh);
        }
      }
      if (pinned) {
        ctx.strokeStyle = '#ffb000';
        ctx.lineWidth = 2 * ratio;
        var cx = (pinned.c + 0.5) * sx, cy = (pinned.q + 0.5) * sy, r = Math.max(6 * ratio, sx);
        ctx.strokeRect(cx - r, cy - r, 2 * r, 2 * r);
      }
    }

    function update() {
      var t = threshold(), s = stats(t);
      root.querySelector('.ex-threshold-value').textContent = String(+t.toPrecision(6));
      root.querySelector('.ex-accepted').textContent = s.accepted;
      if (truth) {
        root.querySelector('.ex-correct').textContent = s.tp;
        root.querySelector('.ex-precision').textContent = fixed(s.precision, 4);
        root.querySelector('.ex-recall').textContent = fixed(s.recall, 4);
        marker.setAttribute('cx', px(s.recall));
        marker.setAttribute('cy', py(s.precision));
      }
      drawOverlay();
      if (shown) describe(shown.q, shown.c);
      renderList();
    }

    // The distance the page knows for cell (q, c): exact for the query's best match, else
    // the embedded 8-bit value (of the cell, or of its group of cells).
    function cellValue(q, c) {
      if (run.best[q] === c) return {exact: true, value: run.distance[q]};
      var v = run.values, r = Math.floor(q / v.cell_rows), k = Math.floor(c / v.cell_cols);
      var code = codes[r * v.cols + k];
      return {exact: false, value: code === 255 ? null : code / 254};
    }

    var info = root.querySelector('.ex-cell');
    function describe(q, c) {
      shown = {q: q, c: c};
      var qi = run.row_offset + q, ci = run.col_offset + c;
      var frames = info.querySelector('.ex-cell-frames');
      frames.textContent = '';
      [[run.rows, qi], [run.columns, ci]].forEach(function (f) {
        var t = thumbnail(f[0], f[1], 'ex-big');
        if (t) frames.appendChild(t);
      });
      info.querySelector('.ex-cell-query').textContent = 'query ' + q + ' \u00b7 ' + frameName(run.rows, qi);
      info.querySelector('.ex-cell-reference').textContent =
          'reference ' + c + ' \u00b7 ' + frameName(run.columns, ci);
      var d = cellValue(q, c), text;
      var candidate = run.kind !== 'loop-closure' || c <= q - run.exclusion;
      if (d.value === null) text = 'distance: no value (no full sequence)';
      else if (d.exact) text = 'distance ' + num(d.value, 6) + ' (exact)';
      else if (run.values.cell_rows === 1 && run.values.cell_cols === 1)
        text = 'distance \u2248 ' + d.value.toFixed(3) + ' (8-bit, \u00b10.002)';
      else
        text = 'distance \u2248 ' + d.value.toFixed(3) + ' (8-bit mean of ' + run.values.cell_rows +
               '\u00d7' + run.values.cell_cols + ' cells)';
      if (!candidate) text += '; not a candidate (within the exclusion)';
      info.querySelector('.ex-cell-distance').textContent = text;
      var b = run.best[q], score;
      if (b < 0) {
        score = 'the query has no answer';
      } else if (b === c) {
        score = run.score_kind + ' score ' + num(run.score[q], 6) + ' \u00b7 the query\'s best match, ' +
                (truth ? (correct(q) ? 'right' : 'wrong') + ', ' : '') +
                (accepted(q, threshold()) ? 'accepted' : 'not accepted') + ' at the threshold' +
                (truth ? ''
                       : runAccepted(q) ? '; accepted by the run' : '; not accepted by the run');
      } else {
        score = 'not the query\'s best match (reference ' + b + ', ' + run.score_kind + ' score ' +
                num(run.score[q], 6) + (truth ? ', ' + (correct(q) ? 'right' : 'wrong') : '') + ')';
      }
      info.querySelector('.ex-cell-score').textContent = score;
      info.querySelector('.ex-cell-truth').textContent =
          !truth || run.positive.charAt(q) === '1'
              ? '' : 'the query has no true place among its candidates';
      root.setAttribute('data-cell', q + ',' + c);
    }

    function cellAt(event) {
      var rect = image.getBoundingClientRect();
      var c = Math.floor((event.clientX - rect.left) / rect.width * R);
      var q = Math.floor((event.clientY - rect.top) / rect.height * Q);
      if (c < 0 || q < 0 || c >= R || q >= Q) return null;
      return {q: q, c: c};
    }
    var wrap = root.querySelector('.ex-matrix');
    wrap.addEventListener('mousemove', function (e) {
      var cell = cellAt(e);
      if (cell) describe(cell.q, cell.c);
    });
    wrap.addEventListener('mouseleave', function () {
      if (pinned) describe(pinned.q, pinned.c);
    });
    function pin(q, c) {
      pinned = {q: q, c: c};
      describe(q, c);
      drawOverlay();
    }
    wrap.addEventListener('click', function (e) {
      var cell = cellAt(e);
      if (cell) { pin(cell.q, cell.c); wrap.focus(); }
    });
    // Arrow keys move the pinned cell by one cell (ten with Shift): every cell is reachable on
    // a downsampled image too.
    wrap.addEventListener('keydown', function (e) {
      var moves = {ArrowLeft: [0, -1], ArrowRight: [0, 1], ArrowUp: [-1, 0], ArrowDown: [1, 0]};
      if (!moves[e.key]) return;
      e.preventDefault();
      var step = e.shiftKey ? 10 : 1, p = pinned || {q: 0, c: 0};
      pin(Math.min(Q - 1, Math.max(0, p.q + moves[e.key][0] * step)),
          Math.min(R - 1, Math.max(0, p.c + moves[e.key][1] * step)));
    });
    slider.addEventListener('input', update);
    root.querySelector('.ex-reset').addEventListener('click', function () {
      slider.value = start();
      update();
    });
    window.addEventListener('resize', drawOverlay);

    // The queries by score, with the frames of the query and of its best match.
    var order = root.querySelector('.ex-order'), filter = root.querySelector('.ex-filter');
    var table = root.querySelector('.ex-queries tbody'), more = root.querySelector('.ex-more');
    var limit = 50;
    function listed() {
      var t = threshold(), list = [];
      for (var q = 0; q < Q; ++q) {
        var f = filter.value, b = run.best[q];
        if (f === 'answered' && b < 0) continue;
        if (f === 'right' && (b < 0 || !correct(q))) continue;
        if (f === 'wrong' && (b < 0 || correct(q))) continue;
        if (f === 'accepted' && !accepted(q, t)) continue;
        if (f === 'run' && !runAccepted(q)) continue;
        if (f === 'unanswered' && b >= 0) continue;
        list.push(q);
      }
      var key = function (q) { return run.best[q] < 0 ? Infinity : run.score[q]; };
      if (order.value === 'confident') list.sort(function (a, b) { return key(a) - key(b) || a - b; });
      else if (order.value === 'doubtful')
        list.sort(function (a, b) { return key(b) - key(a) || a - b; });
      return list;
    }
    function renderList() {
      var list = listed(), t = threshold();
      table.textContent = '';
      for (var i = 0; i < Math.min(limit, list.length); ++i) {
        var q = list[i], b = run.best[q], tr = make('tr');
        tr.setAttribute('data-query', q);
        tr.appendChild(make('td', 'n', String(i + 1)));
        var qc = make('td'), qt = thumbnail(run.rows, run.row_offset + q, 'ex-small');
        if (qt) qc.appendChild(qt);
        qc.appendChild(make('div', '', 'query ' + q + ' \u00b7 ' + frameName(run.rows, run.row_offset + q)));
        tr.appendChild(qc);
        var bc = make('td');
        if (b >= 0) {
          var bt = thumbnail(run.columns, run.col_offset + b, 'ex-small');
          if (bt) bc.appendChild(bt);
          bc.appendChild(make('div', '', 'reference ' + b + ' \u00b7 ' + frameName(run.columns, run.col_offset + b)));
        } else {
          bc.textContent = 'no answer';
        }
        tr.appendChild(bc);
        tr.appendChild(make('td', 'n', b >= 0 ? num(run.score[q], 6) : '\u2013'));
        tr.appendChild(make('td', 'n', b >= 0 ? num(run.distance[q], 6) : '\u2013'));
        if (truth) {
          var verdict = b < 0 ? 'no answer' : correct(q) ? 'right' : 'wrong';
          tr.appendChild(make('td', b < 0 ? 'note' : correct(q) ? 'right' : 'wrong', verdict));
          tr.appendChild(make('td', '', accepted(q, t) ? 'accepted' : ''));
        } else {
          tr.appendChild(make('td', '', accepted(q, t) ? 'accepted' : ''));
          // The run's verdict: accepted, or within Match_threshold but not confirmed.
          var within = !run.untrusted && run.threshold !== null && run.score[q] <= run.threshold;
          tr.appendChild(make('td', b < 0 ? 'note' : '',
                              b < 0 ? 'no answer' : runAccepted(q) ? 'accepted'
                                  : within && run.consistency > 0 ? 'not confirmed' : ''));
        }
        (function (q, b) {
          tr.addEventListener('click', function () { pin(q, b >= 0 ? b : 0); });
        })(q, b);
        table.appendChild(tr);
      }
      root.querySelector('.ex-listed').textContent =
          Math.min(limit, list.length) + ' of ' + list.length + ' queries shown';
      more.hidden = list.length <= limit;
    }
    order.addEventListener('change', function () { limit = 50; renderList(); });
    filter.addEventListener('change', function () { limit = 50; renderList(); });
    more.addEventListener('click', function () { limit += 200; renderList(); });

    root.hidden = false;
    update();
    // At first, the most confident answer.
    var first = -1;
    for (var a = 0; a < answered.length; ++a)
      if (first < 0 || run.score[answered[a]] < run.score[first]) first = answered[a];
    pin(Math.max(first, 0), first >= 0 ? run.best[first] : 0);
  }

  var roots = document.querySelectorAll('.explorer');
  for (var i = 0; i < roots.length; ++i) {
    try {
      Explorer(roots[i]);
    } catch (e) {
      console.error('OpenABLE report: the explorer failed: ' + e);
    }
  }
  document.body.setAttribute('data-explorers', String(roots.length));
});
)js";

}  // namespace

std::uint8_t ExploreCode(float distance) {
  if (!std::isfinite(distance)) return 255;
  return static_cast<std::uint8_t>(std::lround(254.0f * std::clamp(distance, 0.0f, 1.0f)));
}

cv::Mat1b ExploreValues(const cv::Mat1f& matrix, const EvaluationLayout& layout, int& cell_rows,
                        int& cell_cols) {
  const int rows = layout.queries, cols = layout.references;
  cell_rows = (rows + kExploreValuesSide - 1) / kExploreValuesSide;
  cell_cols = (cols + kExploreValuesSide - 1) / kExploreValuesSide;
  const int out_rows = (rows + cell_rows - 1) / cell_rows;
  const int out_cols = (cols + cell_cols - 1) / cell_cols;
  cv::Mat1b out(out_rows, out_cols);
  for (int y = 0; y < out_rows; ++y)
    for (int x = 0; x < out_cols; ++x) {
      double sum = 0;
      int n = 0;
      for (int q = y * cell_rows; q < std::min(rows, (y + 1) * cell_rows); ++q)
        for (int c = x * cell_cols; c < std::min(cols, (x + 1) * cell_cols); ++c) {
          const float d = matrix(layout.row_offset + q, layout.col_offset + c);
          if (std::isfinite(d)) {
            sum += d;
            ++n;
          }
        }
      out(y, x) = n > 0 ? ExploreCode(static_cast<float>(sum / n)) : 255;
    }
  return out;
}

namespace {

// The frame sets of the runs' rows and columns, each once; run_sets[i]: the sets of run i's
// rows and columns.
std::vector<FrameSet> ExplorerFrameSets(const ReportInput& input,
                                        const std::vector<ReportRun>& runs,
                                        std::vector<std::pair<int, int>>& run_sets) {
  std::vector<FrameSet> sets;
  std::map<std::tuple<bool, int, int>, int> set_of;
  const auto set_index = [&](bool row, int first, int count) {
    if (input.frames.same_rows_and_columns) row = false;
    const auto key = std::make_tuple(row, first, count);
    const auto found = set_of.find(key);
    if (found != set_of.end()) return found->second;
    FrameSet set;
    set.row = row;
    set.first = first;
    set.count = count;
    sets.push_back(std::move(set));
    return set_of[key] = static_cast<int>(sets.size()) - 1;
  };
  run_sets.clear();
  for (const ReportRun& run : runs)
    run_sets.emplace_back(set_index(true, run.layout.row_offset, run.layout.queries),
                          set_index(false, run.layout.col_offset, run.layout.references));
  return sets;
}

}  // namespace

std::int64_t ExplorerSteps(const ReportInput& input, const std::vector<ReportRun>& runs) {
  std::vector<std::pair<int, int>> run_sets;
  std::int64_t frames = 0;
  if (input.frames.read)
    for (const FrameSet& set : ExplorerFrameSets(input, runs, run_sets)) frames += set.count;
  return frames + static_cast<std::int64_t>(runs.size());
}

std::string ExplorerSection(const ReportInput& input, const std::vector<ReportRun>& runs,
                            const std::function<void()>& step) {
  const ReportFrames& frames = input.frames;
  std::vector<std::pair<int, int>> run_sets;
  std::vector<FrameSet> sets = ExplorerFrameSets(input, runs, run_sets);
  double frame_count = 0;
  for (const FrameSet& set : sets) frame_count += set.count;
  const double max_pixels =
      frame_count > 0 ? kExploreThumbnailPixels / frame_count : kExploreThumbnailPixels;
  for (FrameSet& set : sets) MakeSheets(frames, max_pixels, set, step);

  const bool truth = input.evaluation != nullptr;
  std::string h =
      "<section id=\"explore\">\n<h2>Explore</h2>\n"
      "<noscript><p class=\"note\">The explorer needs JavaScript; the sections "
      "above and below show the same run without it.</p></noscript>\n";
  h += truth ? "<p class=\"note\">Hover over the matrix to see a cell's two frames, click to keep "
               "it (the arrow keys then move it one cell at a time, ten with Shift). The slider "
               "sets the threshold on the score: the best matches with a score at or below it "
               "are accepted (green when right, red when wrong), counted, and placed on the "
               "precision-recall curve. Distances are those of the normalised matrix: exact for "
               "a query's best match, else quantised to 8 bits.</p>\n"
             : "<p class=\"note\">Hover over the matrix to see a cell's two frames, click to keep "
               "it (the arrow keys then move it one cell at a time, ten with Shift). The slider "
               "sets the threshold on the score: the best matches with a score at or below it "
               "are accepted (orange) and counted; without ground truth no answer is judged. "
               "Distances are those of the normalised matrix: exact for a query's best match, "
               "else quantised to 8 bits.</p>\n";

  // The frames: names and thumbnail sheets, shared by the runs.
  Json set_json = Json::array();
  std::string sheets_html;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const FrameSet& set = sets[s];
    Json j;
    j["first"] = set.first;
    j["count"] = set.count;
    j["cell"] = {set.cell_width, set.cell_height};
    j["columns"] = kSheetColumns;
    j["rows"] = kSheetRows;
    j["names"] = json::Strings(set.names);
    Json ids = Json::array();
    for (std::size_t k = 0; k < set.sheets.size(); ++k) {
      const std::string id = "explore-sheet-" + std::to_string(s) + "-" + std::to_string(k);
      ids.push_back(id);
      sheets_html += "<img id=\"" + id + "\" class=\"sheet\" alt=\"thumbnails of " +
                     std::string(set.row ? "rows " : "columns ") + std::to_string(set.first) + "-" +
                     std::to_string(set.first + set.count - 1) + ", sheet " +
                     std::to_string(k + 1) + "\" src=\"data:image/jpeg;base64," +
                     Base64(set.sheets[k]) + "\">\n";
    }
    j["sheets"] = ids;
    set_json.push_back(j);
  }
  h += "<div hidden>\n" + sheets_html + "</div>\n";
  h += "<script type=\"application/json\" id=\"explore-frames\">" +
       ScriptSafe(json::DumpLine(set_json)) + "</script>\n";
  if (!frames.read)
    h += frames.missing.empty()
             ? std::string("<p class=\"note\">Frames are named, not shown.</p>\n")
             : "<p class=\"note\">Frames are named, not shown: " + HtmlEscape(frames.missing) +
                   "</p>\n";

  for (std::size_t i = 0; i < runs.size(); ++i) {
    const ReportRun& run = runs[i];
    const QueryAnswers& a = run.answers;
    const EvaluationLayout& layout = run.layout;
    const cv::Mat1f& matrix = *run.matrix;
    const std::string n = std::to_string(i);
    const std::string score_kind = run.score.kind == MatchScore::kRatio ? "ratio" : "distance";

    Json j;
    j["label"] = run.label;
    j["kind"] =
        layout.kind == EvaluationLayout::Kind::kLoopClosure ? "loop-closure" : "query-reference";
    j["exclusion"] = run.exclusion;
    j["queries"] = layout.queries;
    j["references"] = layout.references;
    j["row_offset"] = layout.row_offset;
    j["col_offset"] = layout.col_offset;
    j["rows"] = run_sets[i].first;
    j["columns"] = run_sets[i].second;
    j["score_kind"] = score_kind;
    j["truth"] = run.evaluated != nullptr;
    j["consistency"] = run.consistency;
    j["untrusted"] = run.untrusted;
    j["threshold"] = run.threshold >= 0 ? json::Number(run.threshold) : Json();
    Json best = Json::array(), score = Json::array(), distance = Json::array();
    for (int q = 0; q < layout.queries; ++q) {
      const bool answered = q < static_cast<int>(a.best.size()) && a.best[q] >= 0;
      best.push_back(answered ? a.best[q] : -1);
      score.push_back(answered ? json::Number(a.score[q]) : Json());
      distance.push_back(answered && q < static_cast<int>(a.distance.size())
                             ? json::Number(a.distance[q])
                             : Json());
    }
    j["best"] = best;
    j["score"] = score;
    j["distance"] = distance;
    // The run's own matches (the confirmed answers at its operating point).
    j["accepted"] = Digits(a.confirmed, layout.queries);
    Json curve = Json::array();
    if (run.evaluated != nullptr) {
      const PerQueryResult& p = run.evaluated->per_query;
      j["positive_queries"] = p.positive_queries;
      j["correct"] = Digits(p.correct, layout.queries);
      j["positive"] = Digits(p.positive, layout.queries);
      for (const CurvePoint& c : p.curve) curve.push_back({json::Number(c.threshold), c.tp, c.fp});
    } else {
      j["positive_queries"] = 0;
      j["correct"] = "";
      j["positive"] = "";
    }
    j["curve"] = curve;
    int cell_rows = 1, cell_cols = 1;
    const cv::Mat1b values = ExploreValues(matrix, layout, cell_rows, cell_cols);
    j["values"] = {{"rows", values.rows},
                   {"cols", values.cols},
                   {"cell_rows", cell_rows},
                   {"cell_cols", cell_cols}};

    const cv::Mat3b image = MatrixImage(matrix, layout, run.truth);
    const std::string image_png = Base64(EncodePng(image));
    step();
    const double longer = std::max(layout.queries, layout.references);
    const int display_w =
        std::max(1, static_cast<int>(std::lround(kMatrixDisplay * layout.references / longer)));
    const int display_h =
        std::max(1, static_cast<int>(std::lround(kMatrixDisplay * layout.queries / longer)));

    std::string note;
    if (run.consistency > 0)
      note += " The run's own operating point also asks Match_consistency " +
              std::to_string(run.consistency) +
              " to confirm each answer; the slider applies the score alone.";
    if (run.untrusted)
      note +=
          " The run accepted no answer (the auto mode could not trust its choice); the "
          "slider shows what a threshold would accept.";
    if (cell_rows > 1 || cell_cols > 1)
      note += " The block is larger than " + std::to_string(kExploreValuesSide) +
              " cells a side: a cell other than a best match shows the mean of its group of " +
              std::to_string(cell_rows) + " x " + std::to_string(cell_cols) + " cells.";
    if (image.cols != layout.references || image.rows != layout.queries)
      note += " The image is downsampled to " + std::to_string(image.cols) + " x " +
              std::to_string(image.rows) +
              " pixels; clicks and arrow keys still select single cells.";

    h += "<h3>" + HtmlEscape(run.label) + "</h3>\n";
    h += "<script type=\"application/json\" id=\"explore-run-" + n + "\">" +
         ScriptSafe(json::DumpLine(j)) +
         "</script>\n<script type=\"text/plain\" id=\"explore-values-" + n + "\">" +
         Base64(std::string(reinterpret_cast<const char*>(values.data), values.total())) +
         "</script>\n";
    h += "<div class=\"explorer\" id=\"explorer-" + n + "\" data-data=\"explore-run-" + n +
         "\" data-values=\"explore-values-" + n + "\" hidden>\n";
    const std::string reset = run.threshold >= 0
                                  ? "run's operating point (" + FormatNumber(run.threshold, 4) + ")"
                                  : std::string("every answer (no Match_threshold)");
    h += "<div class=\"ex-controls\"><label>threshold (" + score_kind +
         " score) <input type=\"range\" class=\"ex-threshold\"></label> "
         "<output class=\"ex-threshold-value\"></output> "
         "<button type=\"button\" class=\"ex-reset\">" +
         reset + "</button><br>";
    if (run.evaluated != nullptr) {
      const PerQueryResult& p = run.evaluated->per_query;
      h += "accepted <b class=\"ex-accepted\"></b> of " + std::to_string(p.queries - p.unanswered) +
           " answers, right <b class=\"ex-correct\"></b>; precision <b "
           "class=\"ex-precision\"></b>, recall <b class=\"ex-recall\"></b> (of " +
           std::to_string(p.positive_queries) + " queries with a true place)</div>\n";
    } else {
      h += "accepted <b class=\"ex-accepted\"></b> of " + std::to_string(a.answered) +
           " answers at this threshold; the run accepted " + std::to_string(a.Confirmed()) +
           " (no ground truth: no answer is judged)</div>\n";
    }
    if (!note.empty()) h += "<p class=\"note\">" + HtmlEscape(note.substr(1)) + "</p>\n";
    h += "<div class=\"ex-row\">\n<div class=\"ex-matrix\" tabindex=\"0\" style=\"width:" +
         std::to_string(display_w) + "px;height:" + std::to_string(display_h) + "px\">" +
         "<img class=\"ex-image\" alt=\"matrix of " + HtmlEscape(run.label) +
         " to explore\" src=\"data:image/png;base64," + image_png +
         "\"><canvas class=\"ex-overlay\"></canvas></div>\n"
         "<div class=\"ex-side\"><div class=\"ex-pr\"></div>\n<div class=\"ex-cell\">"
         "<div class=\"ex-cell-frames\"></div><div class=\"ex-cell-query\"></div>"
         "<div class=\"ex-cell-reference\"></div><div class=\"ex-cell-distance\"></div>"
         "<div class=\"ex-cell-score\"></div><div class=\"ex-cell-truth note\"></div></div>"
         "</div>\n</div>\n";
    h += "<div class=\"ex-list\"><label>order <select class=\"ex-order\">"
         "<option value=\"confident\">by score, most confident first</option>"
         "<option value=\"doubtful\">by score, least confident first</option>"
         "<option value=\"query\">by query</option></select></label> "
         "<label>show <select class=\"ex-filter\"><option value=\"all\">every query</option>"
         "<option value=\"answered\">answered</option>";
    if (run.evaluated != nullptr)
      h += "<option value=\"right\">right</option><option value=\"wrong\">wrong</option>";
    h += "<option value=\"accepted\">accepted at the threshold</option>";
    if (run.evaluated == nullptr) h += "<option value=\"run\">accepted by the run</option>";
    h += "<option value=\"unanswered\">no answer</option></select></label> "
         "<span class=\"ex-listed note\"></span>\n"
         "<table class=\"ex-queries\"><thead><tr><th>#</th><th>query</th><th>best match</th>"
         "<th>score</th><th>distance</th>" +
         std::string(run.evaluated != nullptr ? "<th>result</th><th>at threshold</th>"
                                              : "<th>at threshold</th><th>the run</th>") +
         "</tr></thead><tbody></tbody></table><button type=\"button\" class=\"ex-more\">show "
         "more</button></div>\n</div>\n";
  }
  h += "<script>" + std::string(kScript) + "</script>\n</section>\n";
  return h;
}

}  // namespace openable
