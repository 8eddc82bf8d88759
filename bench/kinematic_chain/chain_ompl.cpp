// OMPL's KinematicChain benchmark, the C++ side of bench/kinematic_chain_bench.py.
//
// Plans one (planner, seed) run on the chain and horn that plannerlab's generator
// (plannerlab/problem/kinematic_chain.py) builds, read from a geometry file the bench
// writes, and prints one JSON line. Written for Debian's libompl-dev 1.5.2 against
// OMPL's public API; the problem's definitions follow OMPL's demos/KinematicChain.h
// (state space, distance, projection, start and goal), the geometry plannerlab's
// (links as capsules, walls as thin boxes, every non-adjacent link pair checked).
//
// Usage: chain_ompl GEOMETRY PLANNER SEED TIME_S [MOTION]
//   MOTION: "ompl" (OMPL's discrete motion validator at the file's resolution, default)
//           or "grid" (plannerlab's grid: at most grid_step per joint and
//           ceil(sum |dq_i| w_i) steps, the file's edge_weights).

#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/base/ProjectionEvaluator.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/est/BiEST.h>
#include <ompl/geometric/planners/est/EST.h>
#include <ompl/geometric/planners/est/ProjEST.h>
#include <ompl/geometric/planners/kpiece/BKPIECE1.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/pdst/PDST.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/sbl/SBL.h>
#include <ompl/geometric/planners/stride/STRIDE.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace
{
const double kPi = 3.14159265358979323846;

struct Wall  // a box in the plane: centre, yaw, half length, half thickness
{
    double cx, cy, c, s, hl, ht;
};

struct Geometry
{
    unsigned n = 0;
    double link = 0, r_scene = 0, r_self = 0, resolution = 0.0005, grid_step = 0.0125;
    std::vector<double> weights, start, goal;
    std::vector<Wall> walls;
};

Geometry readGeometry(const std::string &file)
{
    std::ifstream in(file);
    if (!in)
        throw std::runtime_error("cannot read " + file);
    Geometry g;
    std::string key;
    auto vec = [&](std::vector<double> &v) {
        v.resize(g.n);
        for (auto &x : v)
            in >> x;
    };
    while (in >> key)
    {
        if (key == "links")
            in >> g.n;
        else if (key == "link_length")
            in >> g.link;
        else if (key == "radius_scene")
            in >> g.r_scene;
        else if (key == "radius_self")
            in >> g.r_self;
        else if (key == "resolution")
            in >> g.resolution;
        else if (key == "grid_step")
            in >> g.grid_step;
        else if (key == "edge_weights")
            vec(g.weights);
        else if (key == "start")
            vec(g.start);
        else if (key == "goal")
            vec(g.goal);
        else if (key == "walls")
        {
            unsigned k;
            in >> k;
            for (unsigned i = 0; i < k; ++i)
            {
                double cx, cy, yaw, hl, ht;
                in >> cx >> cy >> yaw >> hl >> ht;
                g.walls.push_back({cx, cy, std::cos(yaw), std::sin(yaw), hl, ht});
            }
        }
        else
            throw std::runtime_error(file + ": unknown key " + key);
        if (!in)
            throw std::runtime_error(file + ": bad value for " + key);
    }
    if (g.n < 2 || g.start.size() != g.n || g.goal.size() != g.n)
        throw std::runtime_error(file + ": needs links, start and goal");
    if (g.weights.size() != g.n)
        g.weights.assign(g.n, 0.0);
    return g;
}

double wrap(double x)  // into [-pi, pi)
{
    x = std::fmod(x + kPi, 2.0 * kPi);
    if (x < 0)
        x += 2.0 * kPi;
    return x - kPi;
}

// ---------------------------------------------------------------- 2-D distances
double pointSegment2(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay;
    double l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
    t = std::min(1.0, std::max(0.0, t));
    double ex = ax + t * dx - px, ey = ay + t * dy - py;
    return ex * ex + ey * ey;
}

double cross(double ax, double ay, double bx, double by)
{
    return ax * by - ay * bx;
}

bool segmentsCross(const double *p, const double *q)  // p, q: x0 y0 x1 y1
{
    double d1 = cross(q[2] - q[0], q[3] - q[1], p[0] - q[0], p[1] - q[1]);
    double d2 = cross(q[2] - q[0], q[3] - q[1], p[2] - q[0], p[3] - q[1]);
    double d3 = cross(p[2] - p[0], p[3] - p[1], q[0] - p[0], q[1] - p[1]);
    double d4 = cross(p[2] - p[0], p[3] - p[1], q[2] - p[0], q[3] - p[1]);
    return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

// squared distance between two segments in the plane (0 when they cross)
double segmentSegment2(const double *p, const double *q)
{
    if (segmentsCross(p, q))
        return 0.0;
    return std::min(std::min(pointSegment2(p[0], p[1], q[0], q[1], q[2], q[3]),
                             pointSegment2(p[2], p[3], q[0], q[1], q[2], q[3])),
                    std::min(pointSegment2(q[0], q[1], p[0], p[1], p[2], p[3]),
                             pointSegment2(q[2], q[3], p[0], p[1], p[2], p[3])));
}

// is the segment within r of the wall's rectangle?
bool segmentNearWall(const double *p, const Wall &w, double r)
{
    // the segment in the wall's frame
    double ax = w.c * (p[0] - w.cx) + w.s * (p[1] - w.cy), ay = -w.s * (p[0] - w.cx) + w.c * (p[1] - w.cy);
    double bx = w.c * (p[2] - w.cx) + w.s * (p[3] - w.cy), by = -w.s * (p[2] - w.cx) + w.c * (p[3] - w.cy);
    // cull: both ends beyond one side of the grown rectangle
    double hx = w.hl + r, hy = w.ht + r;
    if ((ax > hx && bx > hx) || (ax < -hx && bx < -hx) || (ay > hy && by > hy) || (ay < -hy && by < -hy))
        return false;
    // crossing the rectangle (Liang-Barsky clip)
    double t0 = 0, t1 = 1, dx = bx - ax, dy = by - ay;
    bool inside = true;
    const double pp[4] = {-dx, dx, -dy, dy}, qq[4] = {ax + w.hl, w.hl - ax, ay + w.ht, w.ht - ay};
    for (int i = 0; i < 4 && inside; ++i)
    {
        if (pp[i] == 0)
        {
            if (qq[i] < 0)
                inside = false;
        }
        else
        {
            double t = qq[i] / pp[i];
            if (pp[i] < 0)
                t0 = std::max(t0, t);
            else
                t1 = std::min(t1, t);
            if (t0 > t1)
                inside = false;
        }
    }
    if (inside)
        return true;
    // apart: the distance is an end point's to the rectangle or a corner's to the segment
    double r2 = r * r;
    for (double e : {0.0, 1.0})
    {
        double x = e == 0.0 ? ax : bx, y = e == 0.0 ? ay : by;
        double ex = std::max(std::fabs(x) - w.hl, 0.0), ey = std::max(std::fabs(y) - w.ht, 0.0);
        if (ex * ex + ey * ey < r2)
            return true;
    }
    for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0})
            if (pointSegment2(sx * w.hl, sy * w.ht, ax, ay, bx, by) < r2)
                return true;
    return false;
}

// ---------------------------------------------------------------- the state space
// Every joint a full turn: values in [-pi, pi), interpolation the short way round;
// the distance is the demo's (the sum of the joints' displacements in the plane).
class ChainSpace : public ob::RealVectorStateSpace
{
public:
    ChainSpace(unsigned n, double link) : ob::RealVectorStateSpace(n), link_(link)
    {
        ob::RealVectorBounds b(n);
        b.setLow(-kPi);
        b.setHigh(kPi);
        setBounds(b);
    }

    void registerProjections() override;

    double distance(const ob::State *a, const ob::State *b) const override
    {
        const double *x = a->as<StateType>()->values, *y = b->as<StateType>()->values;
        double ta = 0, tb = 0, dx = 0, dy = 0, d = 0;
        for (unsigned i = 0; i < dimension_; ++i)
        {
            ta += x[i];
            tb += y[i];
            dx += std::cos(ta) - std::cos(tb);
            dy += std::sin(ta) - std::sin(tb);
            d += std::sqrt(dx * dx + dy * dy);
        }
        return d * link_;
    }

    void enforceBounds(ob::State *s) const override
    {
        double *x = s->as<StateType>()->values;
        for (unsigned i = 0; i < dimension_; ++i)
            x[i] = wrap(x[i]);
    }

    bool satisfiesBounds(const ob::State *s) const override
    {
        const double *x = s->as<StateType>()->values;
        for (unsigned i = 0; i < dimension_; ++i)
            if (x[i] < -kPi || x[i] > kPi)
                return false;
        return true;
    }

    void interpolate(const ob::State *from, const ob::State *to, double t, ob::State *out) const override
    {
        const double *a = from->as<StateType>()->values, *b = to->as<StateType>()->values;
        double *o = out->as<StateType>()->values;
        for (unsigned i = 0; i < dimension_; ++i)
            o[i] = wrap(a[i] + t * wrap(b[i] - a[i]));
    }

private:
    double link_;
};

// The demo's projection: a random one onto max(2, ceil(ln n)) dimensions.
class ChainProjection : public ob::ProjectionEvaluator
{
public:
    ChainProjection(const ob::StateSpace *space) : ob::ProjectionEvaluator(space)
    {
        unsigned n = space->getDimension();
        dim_ = std::max(2u, (unsigned)std::ceil(std::log((double)n)));
        matrix_.computeRandom(n, dim_);
    }
    unsigned getDimension() const override
    {
        return dim_;
    }
    void project(const ob::State *s, Eigen::Ref<Eigen::VectorXd> out) const override
    {
        matrix_.project(s->as<ob::RealVectorStateSpace::StateType>()->values, out);
    }

private:
    unsigned dim_;
    ob::ProjectionMatrix matrix_;
};

void ChainSpace::registerProjections()
{
    registerDefaultProjection(std::make_shared<ChainProjection>(this));
}

// ---------------------------------------------------------------- validity
class ChainValidity : public ob::StateValidityChecker
{
public:
    ChainValidity(const ob::SpaceInformationPtr &si, const Geometry &g) : ob::StateValidityChecker(si), g_(g)
    {
        seg_.resize(4 * g.n);
    }

    bool isValid(const ob::State *s) const override
    {
        ++checks;
        const double *q = s->as<ob::RealVectorStateSpace::StateType>()->values;
        double th = 0, x = 0, y = 0;
        for (unsigned i = 0; i < g_.n; ++i)
        {
            th += q[i];
            double *p = &seg_[4 * i];
            p[0] = x;
            p[1] = y;
            x += std::cos(th) * g_.link;
            y += std::sin(th) * g_.link;
            p[2] = x;
            p[3] = y;
        }
        double self2 = 4.0 * g_.r_self * g_.r_self;
        for (unsigned i = 0; i + 2 < g_.n; ++i)
            for (unsigned j = i + 2; j < g_.n; ++j)
            {
                const double *a = &seg_[4 * i], *b = &seg_[4 * j];
                // cull: the ends' bounding circles (each link is g_.link long)
                double mx = 0.5 * (a[0] + a[2] - b[0] - b[2]), my = 0.5 * (a[1] + a[3] - b[1] - b[3]);
                double reach = g_.link + 2.0 * g_.r_self;
                if (mx * mx + my * my >= reach * reach)
                    continue;
                if (segmentSegment2(a, b) < self2)
                    return false;
            }
        for (unsigned i = 0; i < g_.n; ++i)
            for (const Wall &w : g_.walls)
                if (segmentNearWall(&seg_[4 * i], w, g_.r_scene))
                    return false;
        return true;
    }

    mutable unsigned long long checks = 0;

private:
    const Geometry &g_;
    mutable std::vector<double> seg_;
};

// plannerlab's grid: n = max(ceil(max |dq| / step), ceil(sum |dq_i| w_i)), states j / n
class GridMotionValidator : public ob::MotionValidator
{
public:
    GridMotionValidator(const ob::SpaceInformationPtr &si, const Geometry &g) : ob::MotionValidator(si), g_(g)
    {
    }

    unsigned count(const ob::State *a, const ob::State *b) const
    {
        const double *x = a->as<ob::RealVectorStateSpace::StateType>()->values;
        const double *y = b->as<ob::RealVectorStateSpace::StateType>()->values;
        double span = 0, metric = 0;
        for (unsigned i = 0; i < g_.n; ++i)
        {
            double d = std::fabs(wrap(y[i] - x[i]));
            span = std::max(span, d);
            metric += d * g_.weights[i];
        }
        return (unsigned)std::max(1.0, std::max(std::ceil(span / g_.grid_step - 1e-12), std::ceil(metric - 1e-12)));
    }

    bool checkMotion(const ob::State *a, const ob::State *b) const override
    {
        if (!si_->isValid(b))
        {
            ++invalid_;
            return false;
        }
        unsigned n = count(a, b);
        ob::State *s = si_->allocState();
        bool ok = true;
        // coarse to fine, as OMPL's discrete validator
        std::vector<std::pair<unsigned, unsigned>> q{{1, n - 1}};
        for (std::size_t k = 0; k < q.size() && ok; ++k)
        {
            auto [lo, hi] = q[k];
            if (lo > hi)
                continue;
            unsigned mid = (lo + hi) / 2;
            si_->getStateSpace()->interpolate(a, b, (double)mid / n, s);
            if (!si_->isValid(s))
                ok = false;
            q.push_back({lo, mid - 1});
            q.push_back({mid + 1, hi});
        }
        si_->freeState(s);
        ok ? ++valid_ : ++invalid_;
        return ok;
    }

    bool checkMotion(const ob::State *a, const ob::State *b, std::pair<ob::State *, double> &last) const override
    {
        unsigned n = count(a, b);
        ob::State *s = si_->allocState();
        for (unsigned j = 1; j <= n; ++j)
        {
            si_->getStateSpace()->interpolate(a, b, (double)j / n, s);
            if (!si_->isValid(s))
            {
                last.second = (double)(j - 1) / n;
                if (last.first != nullptr)
                    si_->getStateSpace()->interpolate(a, b, last.second, last.first);
                si_->freeState(s);
                ++invalid_;
                return false;
            }
        }
        si_->freeState(s);
        ++valid_;
        return true;
    }

private:
    const Geometry &g_;
};

ob::PlannerPtr makePlanner(const std::string &name, const ob::SpaceInformationPtr &si)
{
    if (name == "RRTConnect")
        return std::make_shared<og::RRTConnect>(si);
    if (name == "RRT")
        return std::make_shared<og::RRT>(si);
    if (name == "KPIECE1")
        return std::make_shared<og::KPIECE1>(si);
    if (name == "BKPIECE1")
        return std::make_shared<og::BKPIECE1>(si);
    if (name == "LBKPIECE1")
        return std::make_shared<og::LBKPIECE1>(si);
    if (name == "STRIDE")
        return std::make_shared<og::STRIDE>(si);
    if (name == "EST")
        return std::make_shared<og::EST>(si);
    if (name == "BiEST")
        return std::make_shared<og::BiEST>(si);
    if (name == "ProjEST")
        return std::make_shared<og::ProjEST>(si);
    if (name == "SBL")
        return std::make_shared<og::SBL>(si);
    if (name == "PDST")
        return std::make_shared<og::PDST>(si);
    if (name == "PRM")
        return std::make_shared<og::PRM>(si);
    if (name == "LazyPRM")
        return std::make_shared<og::LazyPRM>(si);
    throw std::runtime_error("unknown planner " + name +
                             " (RRTConnect, RRT, KPIECE1, BKPIECE1, LBKPIECE1, STRIDE, EST, BiEST, ProjEST, "
                             "SBL, PDST, PRM, LazyPRM)");
}

double seconds(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char **argv)
{
    if (argc < 5)
    {
        std::cerr << "usage: " << argv[0] << " GEOMETRY PLANNER SEED TIME_S [ompl|grid]\n";
        return 2;
    }
    try
    {
        Geometry g = readGeometry(argv[1]);
        std::string planner = argv[2];
        unsigned long seed = std::stoul(argv[3]);
        double time_s = std::stod(argv[4]);
        std::string motion = argc > 5 ? argv[5] : "ompl";
        if (motion != "ompl" && motion != "grid")
            throw std::runtime_error("MOTION must be ompl or grid, got " + motion);
        ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
        ompl::RNG::setSeed(seed);  // before any OMPL object makes its generator

        auto space = std::make_shared<ChainSpace>(g.n, g.link);
        og::SimpleSetup ss(space);
        auto si = ss.getSpaceInformation();
        auto validity = std::make_shared<ChainValidity>(si, g);
        ss.setStateValidityChecker(validity);
        si->setStateValidityCheckingResolution(g.resolution);
        if (motion == "grid")
            si->setMotionValidator(std::make_shared<GridMotionValidator>(si, g));
        ob::ScopedState<> start(space), goal(space);
        for (unsigned i = 0; i < g.n; ++i)
        {
            start[i] = g.start[i];
            goal[i] = g.goal[i];
        }
        ss.setStartAndGoalStates(start, goal);
        if (planner == "state-cost")  // CPU time of a state test: uniform and near the start
        {
            ss.setup();
            auto sampler = si->allocStateSampler();
            ob::State *s = si->allocState();
            std::vector<ob::State *> Q;
            ompl::RNG rng;
            for (int i = 0; i < 200000; ++i)
            {
                Q.push_back(si->allocState());
                if (i % 2 == 0)
                    sampler->sampleUniform(Q.back());
                else
                    for (unsigned j = 0; j < g.n; ++j)
                        Q.back()->as<ob::RealVectorStateSpace::StateType>()->values[j] = g.start[j] + rng.gaussian(0, 0.02);
            }
            for (int half = 0; half < 2; ++half)
            {
                std::clock_t c = std::clock();
                unsigned valid = 0;
                for (std::size_t i = half; i < Q.size(); i += 2)
                    valid += validity->isValid(Q[i]);
                double us = 1e6 * (double)(std::clock() - c) / CLOCKS_PER_SEC / (Q.size() / 2);
                std::cout << (half ? "near start" : "uniform") << ": " << us << " us/state, valid "
                          << (double)valid / (Q.size() / 2) << "\n";
            }
            si->freeState(s);
            for (auto *x : Q)
                si->freeState(x);
            return 0;
        }
        ss.setPlanner(makePlanner(planner, si));
        ss.setup();

        std::clock_t c0 = std::clock();
        auto t0 = std::chrono::steady_clock::now();
        ob::PlannerStatus status = ss.solve(time_s);
        double solve_s = seconds(t0);
        unsigned long long solve_checks = validity->checks;
        bool exact = status == ob::PlannerStatus::EXACT_SOLUTION;
        double simplify_s = 0;
        std::size_t raw = 0;
        std::ostringstream path;
        path.precision(17);
        if (exact)
        {
            raw = ss.getSolutionPath().getStateCount();
            auto t1 = std::chrono::steady_clock::now();
            // within what is left of the time limit (as plannerlab's shortcuts are)
            ss.simplifySolution(std::max(time_s - solve_s, 1e-3));
            simplify_s = seconds(t1);
            const auto &p = ss.getSolutionPath();
            path << "[";
            for (std::size_t k = 0; k < p.getStateCount(); ++k)
            {
                const double *x = p.getState(k)->as<ob::RealVectorStateSpace::StateType>()->values;
                path << (k ? ",[" : "[");
                for (unsigned i = 0; i < g.n; ++i)
                    path << (i ? "," : "") << x[i];
                path << "]";
            }
            path << "]";
        }
        else
            path << "null";
        double cpu_s = (double)(std::clock() - c0) / CLOCKS_PER_SEC;
        std::cout.precision(9);
        std::cout << "{\"side\":\"ompl\",\"planner\":\"" << planner << "\",\"links\":" << g.n << ",\"seed\":" << seed
                  << ",\"motion\":\"" << motion << "\",\"status\":\"" << status.asString() << "\",\"solved\":"
                  << (exact ? "true" : "false") << ",\"solve_s\":" << solve_s << ",\"simplify_s\":" << simplify_s
                  << ",\"time_s\":" << solve_s + simplify_s << ",\"cpu_s\":" << cpu_s << ",\"checks\":" << validity->checks
                  << ",\"solve_checks\":" << solve_checks << ",\"raw_waypoints\":" << raw << ",\"path\":" << path.str()
                  << "}" << std::endl;
    }
    catch (const std::exception &e)
    {
        std::cerr << "chain_ompl: " << e.what() << "\n";
        return 2;
    }
    return 0;
}
