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
// Allocation-free steps: after the first step of a given shape the tape asks
// the heap for nothing. Node storage and gradient blocks are kept (above); the
// pull-back closures are not std::functions (one heap block each when they
// capture more than two words) but live in the tape's own arena, bytes kept
// between steps (PullBackArena below); index arrays (keep) and an op's scratch
// that must outlive its forward (workspace) are slots reused in creation
// order. docs/performance.md, "An allocation-free step", has the counts.
//
// There is no global tape: every op takes the tape it writes to.
#pragma once
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <memory>
#include <new>
#include <type_traits>
#include <typeinfo>
#include <utility>
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

// A read-only list of nodes, an op's inputs: a braced list {a, b} (its array
// lives on the stack for the call) or a vector. A braced list used to become a
// std::vector<Var>, a heap block per concat in every step.
class VarList {
 public:
  VarList() = default;
  // The braced list's array outlives the call that takes the VarList (a full
  // expression), which is all an op needs; a VarList is never stored.
#if defined(__GNUC__) && !defined(__clang__)  // GCC's warning; clang has no such group
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Winit-list-lifetime"
#endif
  VarList(std::initializer_list<Var> list) : data_(list.begin()), size_(list.size()) {}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
  VarList(const std::vector<Var>& list) : data_(list.data()), size_(list.size()) {}
  const Var* begin() const { return data_; }
  const Var* end() const { return data_ + size_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Var operator[](size_t k) const { return data_[k]; }

 private:
  const Var* data_ = nullptr;
  size_t size_ = 0;
};

// Bytes for the pull-back closures of one tape: chunks taken from the heap
// once and handed out again after every reset(), so a step that builds the same
// graph as the last one allocates nothing here. A closure is never moved once
// placed (its node keeps a pointer to it), so chunks never move either.
class PullBackArena {
 public:
  void* allocate(size_t bytes, size_t align) {
    for (;;) {
      if (chunk_ < chunks_.size()) {
        const size_t at = (used_ + align - 1) / align * align;
        if (at + bytes <= chunks_[chunk_].size) {
          used_ = at + bytes;
          return chunks_[chunk_].bytes.get() + at;
        }
        ++chunk_;  // the rest of this chunk stays unused until reset()
        used_ = 0;
        continue;
      }
      // A new chunk, kept from now on: 64 KiB holds a training step's
      // closures (a few hundred of 16-80 bytes); a larger closure gets its own.
      const size_t size = std::max<size_t>(kChunk, bytes + align);
      chunks_.push_back({std::unique_ptr<std::byte[]>(new std::byte[size]), size});
    }
  }
  // Everything handed out is free again (its closures destroyed by the tape).
  void reset() {
    chunk_ = 0;
    used_ = 0;
  }

 private:
  static constexpr size_t kChunk = 64 * 1024;
  struct Chunk {
    std::unique_ptr<std::byte[]> bytes;  // aligned for any closure (operator new[])
    size_t size;
  };
  std::vector<Chunk> chunks_;
  size_t chunk_ = 0, used_ = 0;
};

template <class T>
class Tape {
 public:
  using Scalar = T;

  Tape() = default;
  // Nodes point into the arena; a copy would share closures, so none.
  Tape(const Tape&) = delete;
  Tape& operator=(const Tape&) = delete;
  Tape(Tape&& other) noexcept { *this = std::move(other); }
  Tape& operator=(Tape&& other) noexcept {
    if (this != &other) {
      destroy_pull_backs();
      nodes_ = std::move(other.nodes_);
      size_ = std::exchange(other.size_, 0);
      kept_ = std::move(other.kept_);
      kept_size_ = std::exchange(other.kept_size_, 0);
      workspaces_ = std::move(other.workspaces_);
      workspace_size_ = std::exchange(other.workspace_size_, 0);
      parameter_grads_ = other.parameter_grads_;
      pool_ = std::move(other.pool_);
      sweeps_ = other.sweeps_;
      sweeping_ = false;
      arena_ = std::move(other.arena_);
      other.nodes_.clear();
    }
    return *this;
  }
  ~Tape() { destroy_pull_backs(); }

  // A block that needs no gradient (data, targets, constants). `value` is any
  // Eigen expression (a block, a map, leftCols(6), Constant(...)): it is
  // evaluated straight into the node, with no temporary. It must not read a
  // block of this tape: appending the node may move them (copy those first).
  template <class E>
  Var constant(const Eigen::DenseBase<E>& value) {
    return leaf_impl(value, false);
  }
  // A block whose gradient the caller wants to read after backward() (same rule).
  template <class E>
  Var variable(const Eigen::DenseBase<E>& value) {
    return leaf_impl(value, true);
  }

  // The custom-op hook. Appends a node of shape rows x cols whose value the
  // caller fills (value(out) = ...), then registers its pull-back with
  // on_backward(). needs_grad is true iff some input needs a gradient.
  Var node(Index rows, Index cols, VarList inputs) {
    bool ng = false;
    for (Var v : inputs) ng = ng || needs_grad(v);
    return alloc(rows, cols, ng);
  }
  // Registers the pull-back of `out`, f(Tape&, Var self): it reads grad(self)
  // and adds into its inputs' grads. Skipped when nothing upstream needs it.
  // f is moved into the tape's arena (no heap): capture Vars, sizes and
  // pointers, and keep index arrays with keep() rather than capturing vectors.
  template <class F>
  void on_backward(Var out, F&& f) {
    Node& n = nodes_[check(out)];
    if (!n.needs_grad) return;
    using Closure = std::decay_t<F>;
    static_assert(alignof(Closure) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__,
                  "a pull-back closure aligned beyond what the arena's chunks give");
    if (n.backward) n.backward.destroy_closure();
    void* at = arena_.allocate(sizeof(Closure), alignof(Closure));
    n.backward.closure = new (at) Closure(std::forward<F>(f));
    n.backward.run = [](void* c, Tape& t, Var self) { (*static_cast<Closure*>(c))(t, self); };
    n.backward.destroy = std::is_trivially_destructible_v<Closure> ? nullptr : +[](void* c) {
      static_cast<Closure*>(c)->~Closure();
    };
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
    drop_unused_spares();
    ++sweeps_;
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
      n.backward.run(n.backward.closure, *this, Var{i});
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
  // The slots are reused in creation order: the next step's same op gets the
  // same vector back, its capacity with it.
  int keep(const std::vector<int>& index) {
    if (kept_size_ == int(kept_.size())) kept_.emplace_back();
    kept_[kept_size_].assign(index.begin(), index.end());
    return kept_size_++;
  }
  // The ids of a list of nodes (concat's inputs), kept the same way.
  int keep(VarList vars) {
    if (kept_size_ == int(kept_.size())) kept_.emplace_back();
    std::vector<int>& ids = kept_[kept_size_];
    ids.resize(vars.size());
    for (size_t k = 0; k < vars.size(); ++k) ids[k] = vars[k].id;
    return kept_size_++;
  }
  const std::vector<int>& kept(int slot) const { return kept_[slot]; }

  // Scratch of an op or a loss that lives until the next clear(): its
  // vectors and blocks keep their capacity from one step to the next, so an op
  // that sizes them the same way every step allocates only in the first. Slots
  // are handed out in creation order; a slot holding another type (a
  // different graph) is replaced. S must be default-constructible.
  template <class S>
  S& workspace() {
    if (workspace_size_ == int(workspaces_.size())) workspaces_.emplace_back();
    std::unique_ptr<WorkspaceBase>& slot = workspaces_[size_t(workspace_size_++)];
    if (!slot || slot->type() != typeid(S)) slot = std::make_unique<Workspace<S>>();
    return static_cast<Workspace<S>&>(*slot).value;
  }

  // Forgets the graph, keeps the storage (see the header comment).
  void clear() {
    return_all_grads();
    destroy_pull_backs();
    arena_.reset();
    size_ = 0;
    kept_size_ = 0;
    workspace_size_ = 0;
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
    for (const Spare& g : pool_) b += sizeof(T) * size_t(g.block.size());
    return b;
  }

 private:
  // A node's pull-back: its closure in the arena and how to run and destroy
  // it (a type-erased call without std::function's heap block).
  struct PullBack {
    void* closure = nullptr;
    void (*run)(void* closure, Tape& t, Var self) = nullptr;
    void (*destroy)(void* closure) = nullptr;
    explicit operator bool() const { return run != nullptr; }
    void destroy_closure() {
      if (destroy) destroy(closure);
      *this = PullBack{};
    }
  };
  struct Node {
    Block<T> value, grad;
    PullBack backward;
    bool needs_grad = false;
    bool grad_live = false;      // holds a lent gradient block
    bool grad_returned = false;  // its pull-back ran and the block went back
  };

  // A zeroed block of the node's shape: one of the pool's of that size if
  // there is one, else a new one. Only an exact size is taken (a block resized
  // to another size is a free and a malloc in Eigen): the pool grows until it
  // holds, for every size, as many blocks as a sweep has lent at once, and
  // from then on a step that asks for the same sizes allocates nothing. That
  // costs the few small blocks (psi's rows, N x 1 and N x 3 terms) that a
  // resize would have shared with the large ones. Blocks no sweep has asked
  // for since the last one (a schedule changed M) are freed at the next
  // backward() (drop_unused_spares), so old sizes are not kept.
  void lend(Node& n, bool zero = true) {
    const Index rows = n.value.rows(), cols = n.value.cols();
    size_t pick = pool_.size();
    for (size_t k = pool_.size(); k-- > 0;)
      if (pool_[k].block.size() == rows * cols) {
        pick = k;
        break;
      }
    if (pick < pool_.size()) {
      n.grad.swap(pool_[pick].block);
      std::swap(pool_[pick], pool_.back());
      pool_.pop_back();
    }
    n.grad.resize(rows, cols);  // the same size: only the shape changes, no allocation
    if (zero)
      parallel_rows(rows, [&](Index r0, Index r1) { n.grad.middleRows(r0, r1 - r0).setZero(); });
    n.grad_live = true;
  }
  void give_back(Node& n) {
    pool_.emplace_back();
    pool_.back().block.swap(n.grad);
    pool_.back().sweep = sweeps_;
    n.grad_live = false;
    n.grad_returned = true;
  }
  // Frees the spare blocks that were not lent in the last sweep (sweeps_ is
  // its number until backward() counts the next one).
  void drop_unused_spares() {
    size_t kept = 0;
    for (size_t k = 0; k < pool_.size(); ++k)
      if (pool_[k].sweep >= sweeps_) {
        if (kept != k) std::swap(pool_[kept], pool_[k]);
        ++kept;
      }
    pool_.resize(kept);  // frees the rest (their Blocks destruct); no allocation
  }
  void destroy_pull_backs() {
    for (int i = 0; i < size_ && i < int(nodes_.size()); ++i)
      if (nodes_[i].backward) nodes_[i].backward.destroy_closure();
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
    n.backward = PullBack{};  // destroyed by clear()
    n.grad_live = n.grad_returned = false;
    return Var{size_++};
  }
  template <class E>
  Var leaf_impl(const Eigen::DenseBase<E>& value, bool needs_grad) {
    Var v = alloc(value.rows(), value.cols(), needs_grad);
    nodes_[v.id].value = value;
    return v;
  }

  // A workspace slot: any default-constructible type, known by its typeid.
  struct WorkspaceBase {
    virtual ~WorkspaceBase() = default;
    virtual const std::type_info& type() const = 0;
  };
  template <class S>
  struct Workspace final : WorkspaceBase {
    S value;
    const std::type_info& type() const override { return typeid(S); }
  };
  struct Spare {
    Block<T> block;
    long long sweep = 0;  // the sweep that last gave it back
  };

  std::vector<Node> nodes_;
  int size_ = 0;
  std::vector<std::vector<int>> kept_;
  int kept_size_ = 0;
  std::vector<std::unique_ptr<WorkspaceBase>> workspaces_;
  int workspace_size_ = 0;
  std::vector<T>* parameter_grads_ = nullptr;
  std::vector<Spare> pool_;  // gradient blocks not lent to any node
  long long sweeps_ = 0;     // backward() calls so far
  bool sweeping_ = false;    // inside backward()
  PullBackArena arena_;      // the pull-backs' closures
};

}  // namespace jsa
