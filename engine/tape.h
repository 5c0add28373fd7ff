// The tape: reverse-mode automatic differentiation over blocks.
//
// Every op appends one node (its value, an N x C block) in creation order and,
// if any input needs a gradient, a closure that pulls the node's gradient back
// into its inputs' gradients. backward() seeds d(loss)/d(loss) = 1 and walks the
// nodes in reverse: a plain loop, no recursion, because creation order is already
// a topological order. Gradients accumulate (+=), so a block used twice gets the
// sum of both paths.
//
// Memory: clear() forgets the graph but keeps every node's storage. The next
// iteration builds the same graph with the same shapes, so Eigen's resize() is a
// no-op and nothing is reallocated after the first step.
//
// Gradients are lent, not owned. A node's gradient block is taken from a pool
// when the first pull-back writes into it (zeroed then, not all at once before
// the sweep) and handed back as soon as the node's own pull-back has run: in
// the reverse sweep a gradient is live only between its first consumer and its
// producer, so the sweep holds a few blocks at a time where it used to hold one
// per node (about half of a training step's memory). Leaves (no pull-back)
// keep theirs until the next backward() or clear(), for the caller to read.
// A node nobody wrote a gradient into has a zero gradient: its pull-back is
// skipped, since pull-backs are linear in it. Zeroing a lent block is a pass
// over memory as large as the block (an MLP layer's 3M x width rows), so it is
// spread over the threads, and a pull-back that writes every entry of an
// input's gradient asks for it with grad_to_overwrite() and skips the zeroing
// when it is the first writer.
//
// There is no global tape: every op takes the tape it writes to.
#pragma once
#include <functional>
#include <initializer_list>
#include <vector>

#include "engine/block.h"
#include "engine/check.h"
#include "engine/parallel.h"

namespace jsa {

// A handle to a node: its position on the tape.
struct Var {
  int id = -1;
  bool valid() const { return id >= 0; }
};

template <class T>
class Tape {
 public:
  using Scalar = T;
  // Pull-back of one node: reads grad(self) and adds into its inputs' grads.
  using Backward = std::function<void(Tape&, Var self)>;

  // A block that needs no gradient (data, targets, constants).
  Var constant(const Block<T>& value) { return leaf_impl(value, false); }
  // A block whose gradient the caller wants to read after backward().
  Var variable(const Block<T>& value) { return leaf_impl(value, true); }

  // The custom-op hook. Appends a node of shape rows x cols whose value the
  // caller fills (value(out) = ...), then registers its pull-back with
  // on_backward(). needs_grad is true iff some input needs a gradient.
  Var node(Index rows, Index cols, std::initializer_list<Var> inputs) {
    bool ng = false;
    for (Var v : inputs) ng = ng || needs_grad(v);
    return alloc(rows, cols, ng);
  }
  Var node(Index rows, Index cols, const std::vector<Var>& inputs) {
    bool ng = false;
    for (Var v : inputs) ng = ng || needs_grad(v);
    return alloc(rows, cols, ng);
  }
  // Registers the pull-back of `out`; skipped when nothing upstream needs it.
  void on_backward(Var out, Backward f) {
    if (nodes_[out.id].needs_grad) nodes_[out.id].backward = std::move(f);
  }

  const Block<T>& value(Var v) const { return nodes_[check(v)].value; }
  Block<T>& value(Var v) { return nodes_[check(v)].value; }
  // d(loss)/d(node). In a pull-back: the node's gradient, zero until written.
  // After backward(): a leaf's; an inner node's has been handed back (see the
  // header comment) and asking for it is an error.
  Block<T>& grad(Var v) {
    Node& n = nodes_[check(v)];
    if (!n.grad_live) {
      JSA_CHECK(sweeping_ && !n.grad_returned,
                "the gradient of node " << v.id << " is not kept: only leaves' gradients "
                                        << "outlive backward()");
      lend(n);
    }
    return n.grad;
  }
  // For a pull-back that writes every entry of grad(v): *first is true when no
  // pull-back has written into it yet, and the block's entries are then
  // unspecified (the caller assigns, =); otherwise it holds the sum so far
  // (the caller accumulates, +=).
  Block<T>& grad_to_overwrite(Var v, bool* first) {
    Node& n = nodes_[check(v)];
    *first = !n.grad_live;
    if (*first) {
      JSA_CHECK(sweeping_ && !n.grad_returned,
                "the gradient of node " << v.id << " is not kept: only leaves' gradients "
                                        << "outlive backward()");
      lend(n, /*zero=*/false);
    }
    return n.grad;
  }
  const Block<T>& grad(Var v) const {
    const Node& n = nodes_[check(v)];
    JSA_CHECK(n.grad_live, "node " << v.id << " has no gradient (an inner node after backward(), "
                                   << "or one backward() never reached)");
    return n.grad;
  }
  bool needs_grad(Var v) const { return nodes_[check(v)].needs_grad; }
  Index rows(Var v) const { return value(v).rows(); }
  Index cols(Var v) const { return value(v).cols(); }
  T scalar(Var v) const {
    JSA_CHECK(rows(v) == 1 && cols(v) == 1, "not a scalar: " << rows(v) << "x" << cols(v));
    return value(v)(0, 0);
  }

  // Reverse accumulation from a 1 x 1 node: seed dloss = 1, then run the
  // pull-backs newest first, each gradient lent at its first write and given
  // back after its node's pull-back (header comment).
  void backward(Var loss) {
    JSA_CHECK(rows(loss) == 1 && cols(loss) == 1, "backward() needs a scalar loss");
    return_all_grads();  // a second backward() on one graph starts from zero again
    if (!needs_grad(loss)) return;
    struct Sweep {  // sweeping_ is reset even when a pull-back throws
      bool& on;
      explicit Sweep(bool& flag) : on(flag) { on = true; }
      ~Sweep() { on = false; }
    } sweep(sweeping_);
    grad(loss)(0, 0) = T(1);
    for (int i = loss.id; i >= 0; --i) {
      Node& n = nodes_[i];
      if (!n.needs_grad || !n.backward || !n.grad_live) continue;
      n.backward(*this, Var{i});
      give_back(n);
    }
    // Leaves the loss does not reach have a zero gradient to read.
    for (int i = 0; i < size_; ++i) {
      Node& n = nodes_[i];
      if (n.needs_grad && !n.backward && !n.grad_live) lend(n);
    }
  }

  // Index arrays an op needs in its pull-back (gathers, nearest-neighbour
  // matches) live on the tape too, so they are reused like the blocks.
  int keep(const std::vector<int>& index) {
    if (kept_size_ == int(kept_.size())) kept_.emplace_back();
    kept_[kept_size_].assign(index.begin(), index.end());
    return kept_size_++;
  }
  const std::vector<int>& kept(int slot) const { return kept_[slot]; }

  // Forgets the graph, keeps the storage (see the header comment).
  void clear() {
    return_all_grads();
    for (int i = 0; i < size_; ++i) nodes_[i].backward = nullptr;
    size_ = 0;
    kept_size_ = 0;
  }
  int size() const { return size_; }

  // Where parameter leaves (Parameters::on) add their gradients: nullptr, the
  // default, means the Parameters' own buffer. Tapes that run backward() at
  // the same time on one model each get a buffer of their own (the trainer's
  // shape-parallel step), so no two threads add into the same numbers; the
  // caller sums the buffers afterwards, in a fixed order.
  void set_parameter_grads(std::vector<T>* grads) { parameter_grads_ = grads; }
  std::vector<T>* parameter_grads() const { return parameter_grads_; }

  // Bytes held by node values and gradients, lent or in the pool (for memory reports).
  size_t bytes() const {
    size_t b = 0;
    for (const Node& n : nodes_) b += sizeof(T) * size_t(n.value.size() + n.grad.size());
    for (const Block<T>& g : pool_) b += sizeof(T) * size_t(g.size());
    return b;
  }

 private:
  struct Node {
    Block<T> value, grad;
    Backward backward;
    bool needs_grad = false;
    bool grad_live = false;      // holds a lent gradient block
    bool grad_returned = false;  // its pull-back ran and the block went back
  };

  // A zeroed block of the node's shape: one of the pool's of that size if
  // there is one, else any (resized), else a new one. The sweep asks for the
  // same sizes in the same order every step, so after the first step no block
  // is allocated; when the sizes change (a schedule's M) the old blocks are
  // resized rather than kept.
  void lend(Node& n, bool zero = true) {
    const Index rows = n.value.rows(), cols = n.value.cols();
    size_t pick = pool_.size();
    for (size_t k = pool_.size(); k-- > 0;)
      if (pool_[k].size() == rows * cols) {
        pick = k;
        break;
      }
    if (pick == pool_.size() && !pool_.empty()) pick = pool_.size() - 1;
    if (pick < pool_.size()) {
      n.grad.swap(pool_[pick]);
      pool_[pick].swap(pool_.back());
      pool_.pop_back();
    }
    n.grad.resize(rows, cols);
    if (zero)
      parallel_rows(rows, [&](Index r0, Index r1) { n.grad.middleRows(r0, r1 - r0).setZero(); });
    n.grad_live = true;
  }
  void give_back(Node& n) {
    pool_.emplace_back();
    pool_.back().swap(n.grad);
    n.grad_live = false;
    n.grad_returned = true;
  }
  void return_all_grads() {
    for (int i = 0; i < size_; ++i) {
      Node& n = nodes_[i];
      if (n.grad_live) give_back(n);
      n.grad_returned = false;
    }
  }

  int check(Var v) const {
    JSA_CHECK(v.id >= 0 && v.id < size_, "stale or invalid Var " << v.id);
    return v.id;
  }
  Var alloc(Index rows, Index cols, bool needs_grad) {
    if (size_ == int(nodes_.size())) nodes_.emplace_back();
    Node& n = nodes_[size_];
    n.value.resize(rows, cols);
    n.needs_grad = needs_grad;
    n.backward = nullptr;
    n.grad_live = n.grad_returned = false;
    return Var{size_++};
  }
  Var leaf_impl(const Block<T>& value, bool needs_grad) {
    Var v = alloc(value.rows(), value.cols(), needs_grad);
    nodes_[v.id].value = value;
    return v;
  }

  std::vector<Node> nodes_;
  int size_ = 0;
  std::vector<std::vector<int>> kept_;
  int kept_size_ = 0;
  std::vector<T>* parameter_grads_ = nullptr;
  std::vector<Block<T>> pool_;  // gradient blocks not lent to any node
  bool sweeping_ = false;       // inside backward()
};

}  // namespace jsa
