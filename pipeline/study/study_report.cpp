// docs/ACCURACY.md from the stored study parts: tables, Pareto fronts, the defaults' place, presets; gnuplot plots.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <QFileInfo>
#include <QProcess>
#include <QStandardPaths>
#include <QTemporaryDir>

#include "core/base/error.h"
#include "core/scene/scene.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {
namespace {

// Sections of ACCURACY.md written by hand: carried over word for word from the existing file.
const char* const kKeptSections[] = {"The reference solver", "Normalization", "Volumes", "Tried and not kept"};

std::string f(const char* format, double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

std::string secs(double s)
{
    if (s < 0.01) return f("%.4f", s);
    if (s < 1.0) return f("%.3f", s);
    if (s < 10.0) return f("%.2f", s);
    return f("%.1f", s);
}

std::string err(double e) { return e < 0.0 ? "-" : f("%.4f", e); }

std::string minutes(double s) { return s < 120.0 ? f("%.0f s", s) : f("%.1f min", s / 60.0); }

std::string millions(double n) { return n >= 1e6 ? f("%.0fM", n / 1e6) : f("%.0fk", n / 1e3); }

std::string storageName(bool fp16) { return fp16 ? "fp16" : "fp32"; }

std::string lbConfig(const LbRow& r) { return "grid " + std::to_string(r.grid) + " " + r.steps + " " + storageName(r.fp16); }

// Splits a Markdown file into "## " sections: heading text -> the section including its heading line.
std::map<std::string, std::string> readSections(const std::string& path)
{
    std::map<std::string, std::string> out;
    std::ifstream in(path);
    std::string line, heading, text;
    auto flush = [&] {
        if (!heading.empty()) out[heading] = text;
    };
    while (std::getline(in, line)) {
        if (line.rfind("## ", 0) == 0) {
            flush();
            heading = line.substr(3);
            text.clear();
        }
        if (!heading.empty()) text += line + "\n";
    }
    flush();
    return out;
}

// Trailing blank lines removed, exactly one newline at the end.
std::string trimmed(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return s + "\n";
}

struct Plotter {
    std::string program;                 // empty: no gnuplot
    std::string note;                    // why no plots
    QTemporaryDir work;
    std::string outDir;
    std::vector<std::string> written;

    std::string dataFile(const std::string& name, const std::string& content)
    {
        const std::string p = work.path().toStdString() + "/" + name;
        std::ofstream(p) << content;
        return p;
    }

    // Runs a script that writes outDir/png; records it when it appeared.
    void plot(const std::string& png, const std::string& body)
    {
        if (program.empty()) return;
        const std::string out = outDir + "/" + png;
        std::string script = "set terminal pngcairo size 800,500 font 'Sans,10' noenhanced\nset output '" + out + "'\n" +
                             "set grid lc rgb '#dddddd'\nset key outside right top\n" + body;
        const std::string scriptPath = dataFile(png + ".gp", script);
        QProcess p;
        p.start(QString::fromStdString(program), {QString::fromStdString(scriptPath)});
        if (!p.waitForFinished(120000) || p.exitStatus() != QProcess::NormalExit || p.exitCode() != 0) {
            std::string e = p.readAllStandardError().toStdString();
            while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
            const size_t nl = e.rfind('\n');
            note = "gnuplot failed on " + png + ": " + (nl == std::string::npos ? e : e.substr(nl + 1));
            return;
        }
        if (QFileInfo::exists(QString::fromStdString(out))) written.push_back(out);
    }
};

std::string findGnuplot(std::string* note)
{
    if (const char* env = std::getenv("SYLVA_GNUPLOT")) {
        const QFileInfo fi(QString::fromUtf8(env));
        if (fi.isFile() && fi.isExecutable()) return env;
        *note = std::string("SYLVA_GNUPLOT=") + env + " is not an executable program";
        return {};
    }
    const QString exe = QStandardPaths::findExecutable("gnuplot");
    if (exe.isEmpty()) *note = "gnuplot not found (Debian package gnuplot-nox)";
    return exe.toStdString();
}

const char* const kGridColours[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e"};

// ---------------------------------------------------------------- LB

struct CaseFront {
    std::vector<size_t> front;           // row indices on the front (errFine), by time
    std::set<size_t> onFront;
    long defaultRow = -1;
};

CaseFront frontOf(const LbCase& c)
{
    CaseFront cf;
    std::vector<double> t, e;
    for (size_t i = 0; i < c.rows.size(); ++i) {
        t.push_back(c.rows[i].cpuSeconds);
        e.push_back(c.rows[i].errFine);
        if (c.rows[i].isDefault) cf.defaultRow = long(i);
    }
    cf.front = paretoFront(t, e);
    cf.onFront.insert(cf.front.begin(), cf.front.end());
    return cf;
}

const LbRow* findRow(const LbCase& c, int grid, const std::string& steps, bool fp16)
{
    for (const LbRow& r : c.rows)
        if (r.grid == grid && r.steps == steps && r.fp16 == fp16) return &r;
    return nullptr;
}

// Where a row stands against the front: "on the front" or what dominates it.
std::string standing(const LbCase& c, const CaseFront& cf, size_t row)
{
    if (cf.onFront.count(row)) return "on the front";
    const LbRow& r = c.rows[row];
    const LbRow* best = nullptr;
    for (size_t i : cf.front) {
        const LbRow& x = c.rows[i];
        if (x.cpuSeconds <= r.cpuSeconds && x.errFine <= r.errFine && (!best || x.cpuSeconds < best->cpuSeconds)) best = &x;
    }
    if (!best) return "off the front";
    return "off the front: " + lbConfig(*best) + " takes " + secs(best->cpuSeconds) + " CPU s (" +
           f("%.2f", r.cpuSeconds / best->cpuSeconds) + "x less) at error " + err(best->errFine) + " (" + err(r.errFine) + ")";
}

void lbPlot(Plotter& pl, const LbCase& c, const CaseFront& cf, const std::string& defaultConfig)
{
    std::map<std::pair<int, bool>, std::string> series;
    for (const LbRow& r : c.rows) series[{r.grid, r.fp16}] += secs(r.cpuSeconds) + " " + err(r.errFine) + "\n";
    std::string front, def;
    for (size_t i : cf.front) front += secs(c.rows[i].cpuSeconds) + " " + err(c.rows[i].errFine) + "\n";
    if (cf.defaultRow >= 0) def = secs(c.rows[size_t(cf.defaultRow)].cpuSeconds) + " " + err(c.rows[size_t(cf.defaultRow)].errFine) + "\n";
    std::string cmd = "set logscale xy\nset xlabel 'LB solve, CPU seconds (RGB, 2 threads)'\nset ylabel 'relative L2 error vs the " +
                      std::to_string(c.fineGrid) + " reference (green)'\nset title '" + c.title + "'\nplot ";
    int colour = 0;
    std::map<int, int> colourOf;
    bool first = true;
    for (const auto& [key, data] : series) {
        if (!colourOf.count(key.first)) colourOf[key.first] = colour++;
        const std::string file = pl.dataFile("lb_" + c.name + "_" + std::to_string(key.first) + (key.second ? "_16" : "_32") + ".dat", data);
        cmd += std::string(first ? "" : ", ") + "'" + file + "' using 1:2 with points pt " + (key.second ? "9" : "7") + " ps 1.3 lc rgb '" +
               kGridColours[colourOf[key.first] % 5] + "' title 'grid " + std::to_string(key.first) + " " + storageName(key.second) + "'";
        first = false;
    }
    cmd += ", '" + pl.dataFile("lb_" + c.name + "_front.dat", front) + "' using 1:2 with lines dt 2 lw 1.5 lc rgb 'black' title 'Pareto front'";
    if (!def.empty())
        cmd += ", '" + pl.dataFile("lb_" + c.name + "_default.dat", def) +
               "' using 1:2 with points pt 6 ps 3.5 lw 2 lc rgb 'red' title 'default (" + defaultConfig + ")'";
    pl.plot("lb_" + c.name + ".png", cmd + "\n");
}

std::string lbSection(const LbData& d, Plotter& pl)
{
    std::ostringstream s;
    const int fine = d.cases.empty() ? 128 : d.cases.front().fineGrid;
    s << "## LB lighting: grid, steps and storage against the reference\n\n";
    s << "Every run solves all three channels of its preset with `lb::solveLighting` (the time a user pays; the best of three for "
         "runs under 0.3 s), sun (0.3, 1, 0.2). Its error is that of the green channel against Monte Carlo references "
         "(`solveReference`, lattice beams, the green channel's optics: one solve per grid; R and B behave alike, see the example "
         "above), both normalized as above, relative L2 over the interior nodes. Two errors per run:\n\n";
    s << "- **same grid**: against the reference solved on the run's own density grid: the LB's transport error alone "
         "(lattice directions, discrete phase function, per-step attenuation, steps).\n";
    s << "- **vs " << fine << "**: against the reference on the finest grid (" << fine
      << " nodes on the longest axis), the run's grid sampled trilinearly at that grid's node positions, as the renderer samples it: "
         "the transport error plus what a coarser grid cannot resolve. Resolution only shows in this error, so the Pareto front "
         "(time against this error) and the defaults are judged on it.\n\n";
    s << "Times: the wall clock of the solve on the 2-core machine and its CPU time (all threads), each the best of three runs "
         "under 5 s and of two under 30 s. The machine is shared with other work (load averages at the top), which stretches wall "
         "times but hardly CPU times, so the fronts and the plots use CPU time; on an idle machine a solve's wall time is about "
         "half its CPU time.\n\n";
    s << "Steps: `default` = 2 x the longest grid edge (the seed's), `half` = half of that, `tol 1e-3` / `tol 1e-4` = until the "
         "relative change per step falls below it (checked about every 16 steps, at most 4 x the longest edge). The product's "
         "default for a scene species (" << d.defaultConfig << ") is marked **default**; the plots ring it in red. "
         "A reference's noise adds to a measured error in quadrature: the LB's own error is about sqrt(e^2 - noise^2).\n\n";
    if (!d.note.empty()) s << d.note << "\n\n";

    std::vector<std::string> defaultNotes;
    for (const LbCase& c : d.cases) {
        s << "### " << c.title << "\n\n";
        if (!c.skipped.empty()) {
            s << "Skipped: " << c.skipped << ".\n\n";
            continue;
        }
        const CaseFront cf = frontOf(c);
        lbPlot(pl, c, cf, d.defaultConfig);
        s << "![" << c.name << ": time against error](accuracy/lb_" << c.name << ".png)\n\n";
        s << "| reference grid | nodes | paths | noise | solve time |\n| --- | --- | --- | --- | --- |\n";
        for (const LbReference& r : c.references)
            s << "| " << r.grid << " | " << r.dims << " | " << millions(r.paths) << " | " << err(r.noise) << " | "
              << minutes(r.seconds) << (r.cached ? " (cached)" : "") << " |\n";
        s << "\n| grid | nodes | steps | storage | steps run | wall (s) | CPU (s) | error, same grid | error vs " << c.fineGrid
          << " | |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
        for (size_t i = 0; i < c.rows.size(); ++i) {
            const LbRow& r = c.rows[i];
            std::string mark = cf.onFront.count(i) ? "front" : "";
            if (r.isDefault) mark += mark.empty() ? "**default**" : ", **default**";
            s << "| " << r.grid << " | " << r.dims << " | " << r.steps << " | " << storageName(r.fp16) << " | " << r.stepsTaken << " | "
              << secs(r.seconds) << " | " << secs(r.cpuSeconds) << " | " << err(r.errSame) << " | " << err(r.errFine) << " | " << mark << " |\n";
        }
        s << "\nPareto front (CPU time, error vs " << c.fineGrid << "): ";
        for (size_t k = 0; k < cf.front.size(); ++k) {
            const LbRow& r = c.rows[cf.front[k]];
            s << (k ? "; " : "") << lbConfig(r) << " (" << secs(r.cpuSeconds) << " s, " << err(r.errFine) << ")";
        }
        s << ".\n";
        if (cf.defaultRow >= 0) {
            const std::string st = standing(c, cf, size_t(cf.defaultRow));
            s << "The default is " << st << ".\n";
            defaultNotes.push_back(c.name + ": " + st);
        }
        s << "\n";
    }

    // What the knobs do, over all cases.
    double maxFp16 = 0.0;
    std::map<int, std::vector<double>> fp16Ratio;             // grid -> fp16 CPU / fp32 CPU
    double tolErr = 0.0, tolTime = 0.0, halfErr = 0.0;
    int tolN = 0, halfLower = 0, halfN = 0;
    std::map<std::string, std::string> byGrid;                // case -> "32: e, 64: e, ..."
    for (const LbCase& c : d.cases) {
        for (const LbRow& r : c.rows) {
            if (!r.fp16) continue;
            const LbRow* b = findRow(c, r.grid, r.steps, false);
            if (!b || !(b->cpuSeconds > 0.0)) continue;
            maxFp16 = std::max(maxFp16, std::fabs(r.errFine - b->errFine));
            fp16Ratio[r.grid].push_back(r.cpuSeconds / b->cpuSeconds);
        }
        for (const LbRow& r : c.rows) {
            if (r.fp16 || r.steps != "default") continue;
            byGrid[c.name] += (byGrid[c.name].empty() ? "" : ", ") + std::to_string(r.grid) + ": " + err(r.errFine);
            const LbRow* t = findRow(c, r.grid, "tol 1e-3", false);
            const LbRow* h = findRow(c, r.grid, "half", false);
            if (h) {
                halfErr = std::max(halfErr, std::fabs(h->errFine - r.errFine));
                halfLower += h->errFine < r.errFine;
                ++halfN;
            }
            if (!t || !(r.cpuSeconds > 0.0)) continue;
            tolErr = std::max(tolErr, std::fabs(t->errFine - r.errFine));
            tolTime += t->cpuSeconds / r.cpuSeconds;
            ++tolN;
        }
    }
    s << "### What the knobs buy\n\n";
    if (!fp16Ratio.empty()) {
        s << "- **fp16 storage** changes the error vs " << fine << " by at most " << f("%.1e", maxFp16)
          << " (absolute): nothing next to the model's error. Its CPU time relative to fp32 (median over steps and cases) is";
        bool first = true;
        for (auto& [grid, ratios] : fp16Ratio) {
            std::sort(ratios.begin(), ratios.end());
            s << (first ? " " : ", ") << f("%.2f", ratios[ratios.size() / 2]) << " at " << grid;
            first = false;
        }
        s << ": half the memory always, faster only once the distributions outgrow the caches (PERFORMANCE.md).\n";
    }
    if (tolN > 0) {
        s << "- **Steps**: stopping at a change of 1e-3 per step moves the error vs " << fine << " by at most " << f("%.1e", tolErr)
          << " and costs on average " << f("%.2f", tolTime / tolN) << "x the CPU time of the seed's 2 x longest edge; half those steps "
          << "move it by at most " << f("%.1e", halfErr) << ". The LB's transport error (same-grid column) dwarfs its convergence error.";
        if (halfN > 0 && 2 * halfLower > halfN)
            s << " Fewer steps even lower the error a little (" << halfLower << " of " << halfN
              << " grids): an unconverged field is darker, which offsets the LB's excess brightness (mean LB / mean reference "
                 "about 1.035, see Normalization). That is a cancellation, not accuracy. The default and the presets solve 1 x "
                 "the longest edge (\"half\") because the convergence error it leaves is far below the transport error at "
                 "half the seed's cost, not because of that cancellation.";
        s << "\n";
    }
    s << "- **Grid resolution** is the knob that buys accuracy: error vs " << fine << " at the seed's steps, fp32, by grid:";
    for (const auto& [name, text] : byGrid) s << " " << name << " (" << text << ");";
    s << " the same-grid error stays at the model's transport error at every grid.\n\n";
    return s.str();
}

// ---------------------------------------------------------------- voxelization

std::string voxelSection(const VoxelData& d, Plotter& pl)
{
    std::ostringstream s;
    s << "## Voxelization: sub-cells per cell\n\n";
    s << "A node's density is the share of its cell's s^3 sub-cells that a triangle meets (LB_MODEL.md); the default is 3^3. "
         "A leaf is a surface, so that share falls about as 1/s: the sub-cell count sets the density's scale, an effective leaf "
         "thickness that the preset optics go with (the seed's 3^3), not just a sampling accuracy (column \"total vs 3^3\"). "
         "So the study compares shapes: each run against the " << d.referenceSubcells << "^3 density scaled to the run's total "
         "(the same leaves with the same optical depth overall, placed as finely as "
      << d.referenceSubcells << "^3 places them): the density error (relative L2, interior nodes) and the LB error it causes "
         "(default solve: default steps, fp32, all channels, normalized, relative L2 over the interior nodes, against the LB on "
         "that scaled density). Voxelization time: best of three, 2 threads.\n\n";
    s << "![sub-cells against error](accuracy/voxel.png)\n\n";
    s << "| mesh | grid | sub-cells | voxelize (s) | total vs 3^3 | density error | LB error |\n| --- | --- | --- | --- | --- | --- | --- |\n";
    std::map<std::string, std::string> dens, lbe;
    for (const VoxelRow& r : d.rows) {
        s << "| " << r.caseName << " | " << r.grid << " | " << r.subcells << "^3" << (r.subcells == 3 ? " (default)" : "") << " | "
          << secs(r.voxelSeconds) << " | " << f("%.3f", r.meanVs3) << " | " << err(r.densityErr) << " | " << err(r.lbErr) << " |\n";
        dens[r.caseName] += std::to_string(r.subcells) + " " + err(r.densityErr) + "\n";
        lbe[r.caseName] += std::to_string(r.subcells) + " " + err(r.lbErr) + "\n";
    }
    std::string cmd = "set logscale y\nset xlabel 'sub-cells per cell edge'\nset ylabel 'relative L2 error vs " +
                      std::to_string(d.referenceSubcells) + "^3 sub-cells (same total)'\nset xtics (3, 4, 6, 8)\nset xrange [2.5:8.5]\nplot ";
    int k = 0;
    for (const auto& [name, series] : dens) {
        cmd += std::string(k ? ", " : "") + "'" + pl.dataFile("voxel_d_" + name + ".dat", series) + "' using 1:2 with linespoints pt 7 lc rgb '" +
               kGridColours[k % 5] + "' title '" + name + ": density', '" + pl.dataFile("voxel_l_" + name + ".dat", lbe[name]) +
               "' using 1:2 with linespoints pt 9 dt 2 lc rgb '" + kGridColours[k % 5] + "' title '" + name + ": LB result'";
        ++k;
    }
    pl.plot("voxel.png", cmd + "\n");
    s << "\n";
    for (const auto& entry : dens) {
        const std::string& name = entry.first;
        const VoxelRow *three = nullptr, *finest = nullptr;
        for (const VoxelRow& r : d.rows) {
            if (r.caseName != name) continue;
            if (r.subcells == 3) three = &r;
            if (!finest || r.subcells > finest->subcells) finest = &r;
        }
        if (three && finest && finest != three)
            s << "- " << name << ": 3^3 places the density within " << err(three->densityErr) << " and the LB result within "
              << err(three->lbErr) << " in " << secs(three->voxelSeconds) << " s; " << finest->subcells << "^3 gets "
              << err(finest->lbErr) << " for " << f("%.1f", finest->voxelSeconds / std::max(1e-9, three->voxelSeconds))
              << "x the time, and scales the density by " << f("%.2f", finest->meanVs3) << ".\n";
    }
    s << "\nEvery sub-cell count is on its front (finer costs more time and errs less), and voxelizing is cheap next to the LB "
         "solve; but a finer count also thins the medium (total vs 3^3), which the leaf optics would have to be refitted for. "
         "3^3 stays the default: compare its LB error here with the LB's transport error against the reference (previous section).\n\n";
    return s.str();
}

// ---------------------------------------------------------------- rendering

std::string renderSections(const RenderData& d, Plotter& pl)
{
    std::ostringstream s;
    s << "## Rendering: samples per pixel\n\n";
    s << "Image error = relative L2 of the linear luminance (the `full` picture with its sky, before tone mapping) against a "
         "render of the same scene with " << d.sppReference << " samples per pixel: sqrt(sum (L - L_ref)^2 / sum L_ref^2). "
      << d.sppScene << ", " << d.sppWidth << "x" << d.sppHeight << ". Trace time on 2 cores: wall clock and CPU time (all threads), the best of two; the fronts use CPU time.\n\n";
    s << "![samples per pixel](accuracy/render_spp.png)\n\n| spp | trace wall (s) | trace CPU (s) | image error | |\n| --- | --- | --- | --- | --- |\n";
    std::string data;
    for (const SppRow& r : d.spp) {
        s << "| " << r.spp << " | " << secs(r.traceSeconds) << " | " << secs(r.traceCpu) << " | " << err(r.err) << " | "
          << (r.spp == RenderSettings{}.spp ? "**default**" : "") << " |\n";
        data += secs(r.traceCpu) + " " + err(r.err) + " " + std::to_string(r.spp) + "\n";
    }
    s << "\nEvery row is on the front (more samples cost more and err less); the error falls about as 1/sqrt(spp) once the "
         "pixel is sampled at all: 1 spp is the pixel centre, aliased, 4 spp already averages the leaf edges.\n\n";
    const std::string file = pl.dataFile("spp.dat", data);
    pl.plot("render_spp.png", "set logscale xy\nset xlabel 'trace, CPU seconds (2 threads)'\nset ylabel 'image error (relative L2, luminance)'\nplot '" + file +
                                  "' using 1:2 with linespoints pt 7 ps 1.3 lc rgb '#1b9e77' title 'spp', '' using 1:2:(sprintf('%d spp', $3)) "
                                  "with labels offset 1.5,0.8 notitle\n");

    s << "## Rendering: adaptive transparency and stochastic pruning\n\n";
    std::string sppList;
    for (size_t k = 0; k < d.lodSpps.size(); ++k) sppList += (k ? (k + 1 == d.lodSpps.size() ? " and " : ", ") : "") + std::to_string(d.lodSpps[k]);
    s << d.lodScene << ", " << d.lodWidth << "x" << d.lodHeight << ". **Adaptive transparency** "
         "(`render.alpha_distance`, Geist & Steele, \"A Lighting Model for Fast Rendering of Forest Ecosystems\", section 2.1): "
         "beyond the distance, leaf cut-outs are not tested and cards count as "
         "opaque. **Stochastic pruning** (`render.prune_distance`, Cook et al. 2007): an instance at distance d traces a level of detail "
         "keeping about start / d of its leaf cards, enlarged to keep the leaf area (docs/RENDERING.md). Each setting at "
      << sppList << " spp; image error as above against the forest with both off at " << d.lodReferenceSpp << " spp ("
      << secs(d.lodReferenceSeconds) << " s), and the knob's own change (\"vs off\"): against both off at the same spp. Build: the "
         "acceleration structures, pruned levels included; trace: the best of two.\n\n";
    s << "![adaptive transparency and pruning](accuracy/render_lod.png)\n\n";
    s << "| setting | build (s) | triangles traced | pruned levels (MB) | spp | trace wall (s) | trace CPU (s) | image error | vs off | |\n"
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    const size_t nspp = d.lodSpps.size();
    std::vector<double> t, e;
    for (const LodRow& r : d.lod)
        for (size_t k = 0; k < nspp; ++k) {
            t.push_back(k < r.traceCpu.size() ? r.traceCpu[k] : 0.0);
            e.push_back(k < r.err.size() ? r.err[k] : 0.0);
        }
    const std::vector<size_t> front = paretoFront(t, e);
    const std::set<size_t> onFront(front.begin(), front.end());
    std::map<std::pair<size_t, int>, std::string> series;   // (spp index, family)
    std::string dFront, dLabels;
    std::vector<std::string> frontNames;
    for (size_t i = 0; i < d.lod.size(); ++i) {
        const LodRow& r = d.lod[i];
        if (r.traceSeconds.size() < nspp || r.traceCpu.size() < nspp || r.err.size() < nspp || r.errOff.size() < nspp) continue;
        const int family = r.isDefault ? 3 : (r.pruneDistance == 0.0f ? 0 : (r.alphaDistance == 0.0f ? 1 : 2));
        for (size_t k = 0; k < nspp; ++k) {
            std::string mark = onFront.count(i * nspp + k) ? "front" : "";
            if (r.isDefault) mark += mark.empty() ? "**default**" : ", **default**";
            s << "| " << (k == 0 ? r.label : std::string()) << " | " << (k == 0 ? secs(r.buildSeconds) : std::string()) << " | "
              << (k == 0 ? millions(r.instancedTriangles) : std::string()) << " | "
              << (k == 0 && r.pruneMegabytes > 0 ? f("%.1f", r.pruneMegabytes) : std::string(k == 0 ? "-" : "")) << " | " << d.lodSpps[k]
              << " | " << secs(r.traceSeconds[k]) << " | " << secs(r.traceCpu[k]) << " | " << err(r.err[k]) << " | " << err(r.errOff[k]) << " | "
              << mark << " |\n";
            series[{k, family}] += secs(r.traceCpu[k]) + " " + err(r.err[k]) + "\n";
        }
    }
    for (size_t idx : front) {
        const LodRow& r = d.lod[idx / nspp];
        const size_t k = idx % nspp;
        dFront += secs(r.traceCpu[k]) + " " + err(r.err[k]) + "\n";
        dLabels += secs(r.traceCpu[k]) + " " + err(r.err[k]) + " \"" + r.label + "\"\n";
        frontNames.push_back(r.label + " at " + std::to_string(d.lodSpps[k]) + " spp (" + secs(r.traceCpu[k]) + " CPU s, " +
                             err(r.err[k]) + ")");
    }
    std::string cmd = "set logscale xy\nset xlabel 'trace, CPU seconds (2 threads)'\nset ylabel 'image error vs " + std::to_string(d.lodReferenceSpp) +
                      " spp, both off (relative L2, luminance)'\nplot ";
    cmd += "'" + pl.dataFile("lod_front.dat", dFront) + "' using 1:2 with lines dt 2 lc rgb 'black' title 'Pareto front', '" +
           pl.dataFile("lod_labels.dat", dLabels) + "' using 1:2:3 with labels offset 0,-0.9 font ',8' notitle";
    const char* names[] = {"alpha", "prune", "alpha + prune", "off (default)"};
    const char* colours[] = {"#1b9e77", "#d95f02", "#7570b3", "red"};
    const char* shapes[] = {"6", "7", "9", "5"};
    for (const auto& [key, points] : series) {
        const std::string sf = pl.dataFile("lod_" + std::to_string(key.first) + "_" + std::to_string(key.second) + ".dat", points);
        cmd += ", '" + sf + "' using 1:2 with points pt " + shapes[key.first % 4] + " ps 1.5 lw 1.5 lc rgb '" + colours[key.second] +
               "' title '" + names[key.second] + ", " + std::to_string(d.lodSpps[key.first]) + " spp'";
    }
    pl.plot("render_lod.png", cmd + "\n");
    s << "\nPareto front (trace CPU time, error): ";
    for (size_t i = 0; i < frontNames.size(); ++i) s << (i ? "; " : "") << frontNames[i];
    s << ".\n\n";
    const LodRow* offRow = nullptr;
    for (const LodRow& r : d.lod)
        if (r.isDefault && r.traceCpu.size() == nspp) offRow = &r;
    if (offRow && nspp > 0) {
        const size_t k = nspp - 1;
        s << "At " << d.lodSpps[k] << " spp, against both off (error " << err(offRow->err[k]) << ", trace " << secs(offRow->traceCpu[k])
          << " CPU s):\n\n";
        for (const LodRow& r : d.lod) {
            if (r.isDefault || r.traceCpu.size() != nspp) continue;
            s << "- " << r.label << ": trace CPU x" << f("%.2f", r.traceCpu[k] / offRow->traceCpu[k]) << ", changes the picture by "
              << err(r.errOff[k]) << ", error vs the reference " << err(r.err[k])
              << (r.pruneMegabytes > 0 ? "; pruned levels " + f("%.1f", r.pruneMegabytes) + " MB, build +" +
                                             f("%.2f", r.buildSeconds - offRow->buildSeconds) + " s"
                                       : std::string())
              << ".\n";
        }
        s << "\n";
    }
    return s.str();
}

// ---------------------------------------------------------------- scene scale

std::string resolutionName(const ForestGridRow& r)
{
    if (r.resolution == 0) return "off";
    return r.automatic ? "auto (" + std::to_string(r.resolution) + ")" : std::to_string(r.resolution);
}

std::string sceneSection(const SceneData& d, Plotter& pl)
{
    std::ostringstream s;
    s << "## Scene scale: the forest-level grid and the relighting basis\n\n";
    s << "### The forest-level grid against per-instance solves\n\n";
    s << "The stand: " << d.standScene << ". **Reference**: every instance lit by its own LB grid, cut out of one LB solve over the "
         "whole stand (" << d.referenceDims << " nodes at the species grid's spacing, every tree's density at its place, solved to a "
         "relative change per step under 1e-4 in fp32" << (d.referenceSeconds > 0.0 ? ", " + secs(d.referenceSeconds) + " s" : std::string(", from the grid cache"))
      << "): what a solve per instance with its neighbours around it gives. The trees stand at whole multiples of the grid spacing, "
         "unrotated and unscaled, so each cut-out is the stand grid's own nodes. Each row renders the same stand with the one "
         "species grid (" << d.speciesDims << ", solved to the same tolerance: its step count is the LB section's knob, not "
         "this one's) and `lighting.forest_grid` off or on at a resolution "
         "(nodes along the plants' longest horizontal extent); image error = relative L2 of the LB pass's luminance against the "
         "reference render (the same rays, so only the lighting differs). Factor: per instance, the green channel's "
         "density-weighted mean over the crown relative to the species grid's; the reference's is its cut-out's, a row's the "
         "factor the forest grid applies at the crown centre (the face factors blend in on the crown's sides, in the picture "
         "only). Time: the forest grid's build and solve, wall clock, the best of two.\n\n";
    s << "The reference's factors: interior trees " << f("%.3f", d.referenceInterior) << ", edge trees " << f("%.3f", d.referenceEdge)
      << ", the lone tree " << f("%.3f", d.isolatedFactor) << " (above 1: light the stand scatters onto it). The reference holds: "
         "the lone tree solved alone in the reference's domain differs from its species grid by " << f("%.1e", d.floorErr)
      << " (relative L2 over its crown). The best any factor per instance can do, each instance's species grid scaled by its "
         "reference factor, leaves an image error of " << err(d.oracleErr) << ": the rest is the shading's variation inside a crown "
         "(a tree's stand side darker than its open side), which the face factors only partly hold.\n\n";
    s << "| reference (per-instance solves) | forest grid off | forest grid at the default resolution |\n| --- | --- | --- |\n"
         "| ![reference](accuracy/scene_stand_reference.png) | ![off](accuracy/scene_stand_off.png) | "
         "![default](accuracy/scene_stand_default.png) |\n\n";
    s << "![forest grid resolution against image error](accuracy/scene_forest_grid.png)\n\n";
    s << "| forest grid | nodes | cells a crown | build + solve (s) | image error | factor error, rms | factor error, max | factor interior | "
         "factor edge | |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    std::vector<double> t, e;
    for (const ForestGridRow& r : d.forest) {
        t.push_back(r.seconds);
        e.push_back(r.imageErr);
    }
    const std::vector<size_t> front = paretoFront(t, e);
    const std::set<size_t> onFront(front.begin(), front.end());
    const ForestGridRow* offRow = nullptr;
    long defaultRow = -1;
    std::string data, autoData;
    for (size_t i = 0; i < d.forest.size(); ++i) {
        const ForestGridRow& r = d.forest[i];
        std::string mark = onFront.count(i) ? "front" : "";
        if (r.isDefault) mark += mark.empty() ? "**default** resolution" : ", **default** resolution";
        if (r.resolution == 0) mark += mark.empty() ? "**default** mode" : ", **default** mode";
        s << "| " << resolutionName(r) << " | " << r.dims << " | " << (r.resolution > 0 ? f("%.1f", r.cellsPerCrown) : std::string("-")) << " | "
          << (r.resolution > 0 ? secs(r.seconds) : std::string("-")) << " | " << err(r.imageErr) << " | " << f("%.3f", r.factorRms) << " | "
          << f("%.3f", r.factorMax) << " | " << f("%.3f", r.interior) << " | " << f("%.3f", r.edge) << " | " << mark << " |\n";
        if (r.resolution == 0) offRow = &r;
        else (r.automatic ? autoData : data) += f("%.3f", r.cellsPerCrown) + " " + err(r.imageErr) + "\n";
        if (r.isDefault) defaultRow = long(i);
    }
    s << "\nPareto front (build + solve time, image error): ";
    for (size_t k = 0; k < front.size(); ++k) {
        const ForestGridRow& r = d.forest[front[k]];
        s << (k ? "; " : "") << resolutionName(r) << " (" << secs(r.seconds) << " s, " << err(r.imageErr) << ")";
    }
    s << ".\n";
    if (defaultRow >= 0) {
        const ForestGridRow& r = d.forest[size_t(defaultRow)];
        const ForestGridRow* best = &r;
        for (const ForestGridRow& x : d.forest)
            if (x.resolution > 0 && x.imageErr < best->imageErr) best = &x;
        s << "The default resolution, " << resolutionName(r) << " (" << f("%.1f", r.cellsPerCrown) << " cells a crown), is "
          << (onFront.count(size_t(defaultRow)) ? "on the front" : "off the front");
        if (offRow && offRow->imageErr > 0.0)
            s << ": it removes " << f("%.0f", 100.0 * (1.0 - r.imageErr / offRow->imageErr)) << "% of the picture's error without a forest "
              << "grid (" << err(offRow->imageErr) << " -> " << err(r.imageErr) << ") in " << secs(r.seconds) << " s";
        if (best != &r)
            s << "; the lowest error, " << err(best->imageErr) << ", is at " << resolutionName(*best) << " (" << secs(best->seconds) << " s)";
        s << ". What counts is the cells a crown spans, not the resolution: below about 3 the face factors are off (the lattice's "
             "shapes, not the stand's), the centre factors alone move the picture little, and from about 4 the grid takes off a sixth of "
             "the error. The automatic resolution asks for 4 (at most 32 nodes along the extent: the default forest's 8 m crowns over 220 m "
             "get 1.0, within the 1 s the forest grid may take there: PERFORMANCE.md). The mode stays off by default so that scenes written before the forest grid render the same "
             "picture; `lighting.forest_grid: auto` turns it on where exposure differs.\n\n";
    }
    if (!data.empty()) {
        const std::string file = pl.dataFile("scene_forest.dat", data);
        std::string cmd = "set logscale x\nset xlabel 'forest grid cells across a crown'\n"
                          "set ylabel 'image error vs per-instance solves'\nset yrange [0:*]\nplot '" + file +
                          "' using 1:2 with linespoints pt 7 ps 1.3 lc rgb '#1b9e77' title 'forest grid on'";
        if (!autoData.empty())
            cmd += ", '" + pl.dataFile("scene_forest_auto.dat", autoData) +
                   "' using 1:2 with points pt 6 ps 3 lw 2 lc rgb 'red' title 'automatic resolution (default)'";
        if (offRow) cmd += ", " + err(offRow->imageErr) + " with lines dt 2 lc rgb '#d95f02' title 'forest grid off'";
        cmd += ", " + err(d.oracleErr) + " with lines dt 3 lc rgb '#7570b3' title 'reference factor per instance'";
        pl.plot("scene_forest_grid.png", cmd + "\n");
    }

    s << "### Relighting from a basis against direct solves\n\n";
    s << "The stand's species grid (" << d.speciesDims << ") in the product's default solve (fixed steps, 1 x the longest "
         "edge), solved once per unit boundary along each moving lattice direction "
         "(`lightingBasisFor`), then lit for " << d.suns << " random suns (elevation 5-85 degrees) by the weighted sum of the basis "
         "(`relight`) and by a direct solve with the same storage and steps; error = relative L2 of the relit grid against the direct "
         "one over every node and channel. Times: wall clock (CPU time in brackets); relight and direct solve the median over the "
         "suns. \"Pays after\": the sun changes after which the basis costs less than solving each sun.\n\n";
    s << "| storage | basis solves | build the basis (s) | direct solve (s) | relight (ms) | memory (MB, fp32 grids) | error, median | "
         "error, max | pays after | |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const BasisRow& r : d.basis) {
        const double pays = r.directSeconds > 0.0 ? std::ceil(r.basisSeconds / r.directSeconds) : 0.0;
        s << "| " << storageName(r.fp16) << " | " << r.directions << " | " << secs(r.basisSeconds) << " (" << secs(r.basisCpu) << ") | "
          << secs(r.directSeconds) << " (" << secs(r.directCpu) << ") | " << f("%.1f", r.relightMs) << " | " << f("%.1f", r.megabytes)
          << " | " << f("%.1e", r.errMedian) << " | " << f("%.1e", r.errMax) << " | " << f("%.0f", pays) << " suns | "
          << (r.isDefault ? "**default**" : "") << " |\n";
    }
    s << "\nThe basis is exact in the model (the LB update is linear in the boundary): fp32's error is float rounding, fp16's the "
         "rounding of its stored distributions, both far below the LB's transport error (the LB section). The species' default "
         "storage is marked";
    for (const BasisRow& r : d.basis)
        if (r.isDefault && r.relightMs > 0.0)
            s << ": a relight costs " << f("%.1f", r.relightMs) << " ms against a direct solve's " << secs(r.directSeconds) << " s ("
              << f("%.0f", 1e3 * r.directSeconds / r.relightMs) << "x less)";
    s << ", so the studio's sun dial and time slider relight from the basis once it is built (*Render > Build Relighting Basis*, "
         "`sylva light --basis`).\n\n";
    return s.str();
}

// ---------------------------------------------------------------- presets

std::string presetSection(const LbData* lb, const RenderData* render)
{
    std::ostringstream s;
    s << "## Quality presets\n\n";
    const LbCase* lbCase = nullptr;
    if (lb)
        for (const LbCase& c : lb->cases)
            if (c.skipped.empty() && !lbCase) lbCase = &c;
    s << "Settings to pick, each measured: the LB columns on the " << (lbCase ? lbCase->name : std::string("tree"))
      << " case above (per species; a forest solves each species once), the render columns end to end on the default forest at "
      << (render ? std::to_string(render->lodWidth) + "x" + std::to_string(render->lodHeight) : std::string("reduced size"))
      << " with the preset's LB settings for every species (build and trace; about 4x the trace time at the default 896x448), "
         "image error against the reference preset (the path tracer) with "
      << (render ? std::to_string(render->presetReferenceSpp) : std::string("many"))
      << " spp. Each preset also sets the integrator and the lighting block: `preview` and `final` the LB grid as a radiance "
         "cache after one and two bounces (`lighting.bounces`, `direct` once, `boundary` sun_sky; the choice the ground truth "
         "below measures against Cycles), `reference` the path tracer.\n\n";
    s << "| preset | LB grid, steps, storage | LB time (s) | LB error vs " << (lbCase ? lbCase->fineGrid : 128)
      << " | spp, alpha distance, prune distance | build (s) | trace wall (s) | trace CPU (s) | image error |\n"
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    const CaseFront cf = lbCase ? frontOf(*lbCase) : CaseFront{};
    std::vector<std::string> notes;
    for (const QualityPreset& q : qualityPresets()) {
        const LbRow* row = lbCase ? findRow(*lbCase, q.grid, q.steps, q.fp16) : nullptr;
        const PresetRow* pr = nullptr;
        if (render)
            for (const PresetRow& p : render->presets)
                if (p.name == q.name) pr = &p;
        if (pr && pr->settings != qualityPresetSettings(q)) {   // measured with other settings: not this preset's figures
            notes.push_back(std::string(q.name) + "'s render columns: not measured with its settings (" + qualityPresetSettings(q) +
                            "; `sylva study render` measures them)");
            pr = nullptr;
        }
        auto dist = [](float m) { return m > 0.0f ? f("%g m", m) : std::string("off"); };
        s << "| **" << q.name << "** | " << q.grid << ", " << q.steps << ", " << storageName(q.fp16) << " | "
          << (row ? secs(row->seconds) + " (CPU " + secs(row->cpuSeconds) + ")" : "-") << " | " << (row ? err(row->errFine) : "-") << " | " << q.spp << ", " << dist(q.alphaDistance)
          << ", " << dist(q.pruneDistance) << " | " << (pr ? secs(pr->buildSeconds) : "-") << " | " << (pr ? secs(pr->traceSeconds) : "-")
          << " | " << (pr ? secs(pr->traceCpu) : "-") << " | " << (pr ? err(pr->err) : "-") << " |\n";
        if (row && lbCase) {
            const size_t idx = size_t(row - lbCase->rows.data());
            notes.push_back(std::string(q.name) + "'s LB settings are " + standing(*lbCase, cf, idx));
        }
    }
    s << "\n";
    for (const std::string& n : notes) s << "- " << n << ".\n";
    s << "\n";
    return s.str();
}

} // namespace

void writeReport(const Options& options, const ReportInput& in, Result& result)
{
    const std::string dir = options.outDir.empty() ? std::string(".") : options.outDir;
    const std::string mdPath = dir + "/ACCURACY.md";
    const std::map<std::string, std::string> old = readSections(mdPath);

    Plotter pl;
    pl.outDir = dir + "/accuracy";
    pl.program = findGnuplot(&pl.note);
    if (!pl.work.isValid()) {
        pl.program.clear();
        pl.note = "no temporary folder for the plot data";
    }

    std::ostringstream md;
    md << "# Accuracy\n\n";
    md << "How far the LB lighting (`sylva light`, [LB_MODEL.md](LB_MODEL.md)) is from the light transport it approximates, "
          "and what each speed knob costs in accuracy and buys in time. The yardstick is a Monte Carlo reference solver "
          "(`core/reference/mc_reference.h`, `sylva reference`): it solves the volumetric radiative transfer on the same density "
          "grid with the same optics, is slow, and is exact in the limit of many paths, with a standard error per node.\n\n";
    md << "**This file is generated** by `sylva study all` (`pipeline/study/`; `sylva study lb|voxel|render|scene` reruns one part and "
          "rewrites the file from the stored numbers of the others, `accuracy/*.json`; `--quick` is the small version CI runs). "
          "The sections \"The reference solver\", \"Normalization\", \"Volumes\" and \"Tried and not kept\" are written by hand "
          "and carried over word for word; edit them here, everything else in the code.\n\n";
    md << "| part | measured | on | took | load average (start, end) |\n| --- | --- | --- | --- | --- |\n";
    auto runLine = [&](const char* name, const RunInfo& r) {
        md << "| " << name << " | " << r.date << (r.quick ? " (--quick)" : "") << " | " << r.machine << " | " << minutes(r.seconds) << " | "
           << f("%.1f", r.loadBefore) << ", " << f("%.1f", r.loadAfter) << " |\n";
    };
    if (in.lb) {
        runLine("LB", in.lb->run);
        double refSeconds = 0.0;
        bool anyCached = false;
        for (const LbCase& c : in.lb->cases)
            for (const LbReference& r : c.references) {
                if (r.cached) {
                    refSeconds += r.seconds;
                    anyCached = true;
                }
            }
        if (anyCached)
            md << "| LB references | solved once, then read from the grid cache | | " << minutes(refSeconds) << " (not in the LB time above) | |\n";
    }
    if (in.voxel) runLine("voxelization", in.voxel->run);
    if (in.render) runLine("rendering", in.render->run);
    if (in.scene) runLine("scene scale", in.scene->run);
    md << "\n";

    for (const char* name : kKeptSections) {
        auto it = old.find(name);
        if (it != old.end()) md << trimmed(it->second) << "\n";
        else md << "## " << name << "\n\n(Written by hand; not present in " << mdPath << ": see the repository's docs/ACCURACY.md.)\n\n";
    }
    if (in.lb) md << lbSection(*in.lb, pl);
    else md << "## LB lighting: grid, steps and storage against the reference\n\nNot measured yet: `sylva study lb`.\n\n";
    if (in.voxel) md << voxelSection(*in.voxel, pl);
    else md << "## Voxelization: sub-cells per cell\n\nNot measured yet: `sylva study voxel`.\n\n";
    if (in.render) md << renderSections(*in.render, pl);
    else md << "## Rendering\n\nNot measured yet: `sylva study render`.\n\n";
    md << presetSection(in.lb, in.render);
    if (in.scene) md << sceneSection(*in.scene, pl);
    else md << "## Scene scale: the forest-level grid and the relighting basis\n\nNot measured yet: `sylva study scene`.\n\n";
    {   // the sky's lights, written by `sylva study sky` (measureSky) and kept until rerun
        std::ifstream sky(dir + "/accuracy/sky.md");
        if (sky) md << sky.rdbuf();
        else md << "## Sky light: virtual lights, interleaving and samples\n\nNot measured yet: `sylva study sky`.\n\n";
    }
    {   // the ground truth against Cycles, written by `sylva study truth` (measureTruth) and kept until rerun
        std::ifstream truth(dir + "/accuracy/truth.md");
        if (truth) md << truth.rdbuf();
        else md << "## Ground truth: Sylva against Cycles\n\nNot measured yet: `sylva study truth` (needs `blender`).\n\n";
    }
    if (pl.program.empty() || !pl.note.empty()) md << "Plots: skipped (" << pl.note << ").\n";

    AtomicFile file(mdPath);
    file.write(md.str());
    file.commit();
    result.markdown = mdPath;
    result.plots = pl.written;
    result.plotNote = pl.note;
}

} // namespace sylva::study
