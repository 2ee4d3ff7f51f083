// Bipartite Location Graph (thesis §3.2.3, Figure 3.10). See location_graph.h.
#include "core/svrc/location_graph.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <new>
#include "core/util/grow.h"

namespace svrc::refine {

namespace {
// Block capacities come in classes 2, 3, 4, 6, 8, 12, 16, 24, ...: class
// 2j holds 2^(j+1) entries, class 2j+1 holds 3·2^j (§8 item 45). Most cells
// and objects hold a handful of links (bounded ply, Lemma 6); steps of 1.5
// leave a third as much room unused on average as steps of 2, and the
// smallest block (2) fits the many arrays of one or two links.
constexpr uint32_t ClassCap(uint32_t k) { return (k & 1) == 0 ? uint32_t{2} << (k / 2) : uint32_t{3} << (k / 2); }
// The class of a block of `cap` entries (a ClassCap value). A power of two
// tested by cap & (cap − 1), not std::has_single_bit: that is a popcount,
// which without -mpopcnt (x86-64 baseline) is a call into libgcc (0.5% of
// cube --max-volume 1e-5's instructions, session 25).
constexpr uint32_t CapClass(uint32_t cap) {
  return (cap & (cap - 1)) == 0 ? 2 * (std::countr_zero(cap) - 1) : 2 * std::countr_zero(cap / 3) + 1;
}
// The smallest class capacity >= size (size >= 1).
constexpr uint32_t FitCap(uint32_t size) {
  if (size <= 2) return 2;
  const uint32_t p = std::bit_ceil(size);  // p/2 < size <= p
  return size <= p / 4 * 3 ? p / 4 * 3 : p;
}
static_assert(ClassCap(0) == 2 && ClassCap(1) == 3 && ClassCap(2) == 4 && ClassCap(3) == 6 && ClassCap(5) == 12);
static_assert(CapClass(2) == 0 && CapClass(3) == 1 && CapClass(24) == 7 && CapClass(32) == 8);
static_assert(FitCap(1) == 2 && FitCap(3) == 3 && FitCap(5) == 6 && FitCap(7) == 8 && FitCap(9) == 12 && FitCap(13) == 16);
}  // namespace

template <typename Entry>
void LocationGraph::Arena<Entry>::Append(Span& s, const Entry& e) {
  if (s.size == s.cap) {
    const uint32_t cap = s.cap == 0 ? ClassCap(0) : ClassCap(CapClass(s.cap) + 1);
    std::vector<uint32_t>& from = free_[CapClass(cap)];
    uint32_t offset;
    if (!from.empty()) {
      offset = from.back();
      from.pop_back();
    } else {
      offset = static_cast<uint32_t>(pool_.size());
      util::ReserveForAppend(pool_, cap);
      pool_.resize(pool_.size() + cap);
    }
    if (s.size > 0) std::memcpy(pool_.data() + offset, pool_.data() + s.offset, s.size * sizeof(Entry));
    if (s.cap != 0) free_[CapClass(s.cap)].push_back(s.offset);
    s.offset = offset;
    s.cap = cap;
  }
  pool_[s.offset + s.size] = e;
  ++s.size;
}

template <typename Entry>
void LocationGraph::Arena<Entry>::Erase(Span& s, uint32_t i) {
  Entry* d = pool_.data() + s.offset;
  std::memmove(d + i, d + i + 1, (s.size - i - 1) * sizeof(Entry));
  --s.size;
}

template <typename Entry>
void LocationGraph::Arena<Entry>::Release(Span& s) {
  if (s.cap != 0) free_[CapClass(s.cap)].push_back(s.offset);
  s = Span{};
}

template <typename Entry>
bool LocationGraph::Arena<Entry>::WouldGrow(const Span& s) const {
  if (s.size < s.cap) return false;
  const uint32_t cap = s.cap == 0 ? ClassCap(0) : ClassCap(CapClass(s.cap) + 1);
  return free_[CapClass(cap)].empty() && pool_.size() + cap > pool_.capacity();
}

template <typename Entry>
void LocationGraph::Arena<Entry>::Compact(const std::vector<Span*>& spans) {
  // Blocks only move down (sorted by offset, each packed block no larger than
  // the one it leaves), so one forward pass of memmoves packs them in place.
  uint32_t next = 0;
  for (Span* s : spans) {
    if (s->size == 0) {
      s->offset = 0;
      s->cap = 0;
      continue;
    }
    const uint32_t cap = FitCap(s->size);
    if (s->offset != next) std::memmove(pool_.data() + next, pool_.data() + s->offset, s->size * sizeof(Entry));
    s->offset = next;
    s->cap = cap;
    next += cap;
  }
  pool_.resize(next);
  for (auto& f : free_) f.clear();
}

namespace {
// The packed size of arrays of these sizes (Arena::Compact's blocks).
uint64_t PackedSize(uint32_t size) { return size == 0 ? 0 : FitCap(size); }
}  // namespace

template <typename Entry>
void LocationGraph::CompactIfSparse(Arena<Entry>& arena, std::vector<Span*>& spans) {
  uint64_t total = 0;
  for (const Span* s : spans) total += PackedSize(s->size);
  if (3 * total > 2 * arena.PoolSize()) return;
  std::sort(spans.begin(), spans.end(), [](const Span* a, const Span* b) { return a->offset < b->offset; });
  arena.Compact(spans);
  ++stats_.compactions;
}

void LocationGraph::MaybeCompactCells() {
  std::vector<Span*> spans;
  for (util::PodVector<CellSpanT>& mesh_spans : cell_spans_) {
    for (CellSpanT& s : mesh_spans) {
      if (s.cap != 0) spans.push_back(&s);
    }
  }
  CompactIfSparse(cell_arena_, spans);
}

void LocationGraph::MaybeCompactObjects() {
  std::vector<Span*> spans;
  for (util::PodVector<Span>* list : {&ball_spans_, &collar_spans_}) {
    for (Span& s : *list) {
      if (s.cap != 0) spans.push_back(&s);
    }
  }
  CompactIfSparse(object_arena_, spans);
}

inline LocationGraph::CellSpanT& LocationGraph::CellSpan(MeshId mesh, uint32_t cell) {
  if (mesh.value() < cell_spans_.size() && cell < cell_spans_[mesh.value()].size()) [[likely]] {
    return cell_spans_[mesh.value()][cell];
  }
  if (cell_spans_.size() <= mesh.value()) cell_spans_.resize(mesh.value() + 1);
  util::PodVector<CellSpanT>& spans = cell_spans_[mesh.value()];
  if (spans.size() <= cell) {
    util::ReserveForAppend(spans, cell + 1 - spans.size());
    spans.resize(cell + 1);
  }
  return spans[cell];
}

// The cell's unresolved count went 0 -> 1 / 1 -> 0: it joins / leaves its
// mesh's list of unresolved cells (swap with the last on removal).
void LocationGraph::EnterUnresolved(MeshId mesh, uint32_t cell, CellSpanT& cs) {
  if (unresolved_cells_.size() <= mesh.value()) unresolved_cells_.resize(mesh.value() + 1);
  std::vector<uint32_t>& list = unresolved_cells_[mesh.value()];
  cs.upos = static_cast<uint32_t>(list.size());
  list.push_back(cell);
}

void LocationGraph::LeaveUnresolved(MeshId mesh, CellSpanT& cs) {
  std::vector<uint32_t>& list = unresolved_cells_[mesh.value()];
  const uint32_t last = list.back();
  list[cs.upos] = last;
  cell_spans_[mesh.value()][last].upos = cs.upos;
  list.pop_back();
}

inline LocationGraph::Span& LocationGraph::ObjectSpan(LocationObject object) {
  util::PodVector<Span>& spans = object.kind == ObjectKind::kBall ? ball_spans_ : collar_spans_;
  if (spans.size() <= object.id) [[unlikely]] {
    util::ReserveForAppend(spans, object.id + 1 - spans.size());
    spans.resize(object.id + 1);
  }
  return spans[object.id];
}

inline const LocationGraph::Span* LocationGraph::FindObjectSpan(LocationObject object) const {
  const util::PodVector<Span>& spans = object.kind == ObjectKind::kBall ? ball_spans_ : collar_spans_;
  return spans.size() <= object.id ? nullptr : &spans[object.id];
}

uint32_t LocationGraph::NumObjectLinks(LocationObject object) const {
  const Span* os = FindObjectSpan(object);
  return os == nullptr ? 0 : os->size;
}

inline uint32_t LocationGraph::CellPos(const Span& cs, LocationObject object) const {
  const CellEntry* e = cell_arena_.Data(cs);
  for (uint32_t i = 0; i < cs.size; ++i) {
    if (e[i].Is(object)) return i;
  }
  return kNil;
}

inline uint32_t LocationGraph::ObjectPosFromBack(const Span& os, MeshId mesh, uint32_t cell) const {
  const ObjectEntry* e = object_arena_.Data(os);
  for (uint32_t i = os.size; i-- > 0;) {
    if (e[i].cell == cell && e[i].mesh == mesh.value()) return i;
  }
  return kNil;
}

inline uint32_t LocationGraph::ObjectPos(const Span& os, MeshId mesh, uint32_t cell) const {
  const ObjectEntry* e = object_arena_.Data(os);
  for (uint32_t i = 0; i < os.size; ++i) {
    if (e[i].cell == cell && e[i].mesh == mesh.value()) return i;
  }
  return kNil;
}

bool LocationGraph::IsLinked(MeshId mesh, uint32_t cell, LocationObject object) const {
  // Scan the shorter of the two arrays: early in a run one cell can hold
  // thousands of unresolved points, and an input object can be linked to many
  // cells; the other array is then short (bounded ply, Lemma 6).
  const CellSpanT* cs = FindCellSpan(mesh, cell);
  const Span* os = FindObjectSpan(object);
  if (cs == nullptr || os == nullptr || cs->size == 0 || os->size == 0) return false;
  if (cs->size <= os->size) return CellPos(*cs, object) != kNil;
  return ObjectPos(*os, mesh, cell) != kNil;
}

AddLinkResult LocationGraph::AddLink(MeshId mesh, uint32_t cell, LocationObject object,
                                     const LinkFacts& facts, BallStore* balls) {
  AddLinkResult result;
  if (object.id > CellEntry::kIdMask) [[unlikely]] {
    // Not representable in a cell entry; the refiner reports an allocation
    // failure as RESOURCE_EXHAUSTED "out of memory".
    throw std::bad_alloc();
  }
  // One lookup per side (the spans are created here if new; an empty span
  // is no link). The duplicate test scans the shorter array, as IsLinked.
  CellSpanT& cs = CellSpan(mesh, cell);
  Span& os = ObjectSpan(object);
  if (cs.size != 0 && os.size != 0 &&
      (cs.size <= os.size ? CellPos(cs, object) : ObjectPos(os, mesh, cell)) != kNil) {
    ++stats_.duplicates_refused;
    return result;
  }
  if (cell_arena_.WouldGrow(cs)) [[unlikely]] MaybeCompactCells();
  if (object_arena_.WouldGrow(os)) [[unlikely]] MaybeCompactObjects();
  cell_arena_.Append(cs, CellEntry::Make(object, facts.unresolved));
  object_arena_.Append(os, ObjectEntry{mesh.value(), cell});
  ++num_links_;
  ++stats_.links_added;
  result.added = true;

  if (facts.unresolved) {
    result.cell_became_unresolved = (cs.unresolved == 0);
    if (cs.unresolved++ == 0) EnterUnresolved(mesh, cell, cs);
  }
  // Figure 3.10: a ConfBall with the cell's vertex strictly inside is
  // encroached; native vertices trigger at once, others on the second,
  // different encroacher.
  if (object.kind == ObjectKind::kBall && facts.encroaches && balls != nullptr) {
    const BallId b(object.id);
    if (balls->Kind(b) == BallKind::kConf) {
      result.encroach = balls->RecordEncroacher(b, facts.vertex_point, facts.native);
    }
  }
  return result;
}

void LocationGraph::RemoveAt(MeshId mesh, CellSpanT& cs, uint32_t ci, Span& os, uint32_t oi) {
  if (cell_arena_.Data(cs)[ci].unresolved() && --cs.unresolved == 0) LeaveUnresolved(mesh, cs);
  cell_arena_.Erase(cs, ci);
  object_arena_.Erase(os, oi);
  --num_links_;
  ++stats_.links_removed;
}

bool LocationGraph::RemoveLink(MeshId mesh, uint32_t cell, LocationObject object) {
  const CellSpanT* cs = FindCellSpan(mesh, cell);
  const Span* os = FindObjectSpan(object);
  if (cs == nullptr || os == nullptr) return false;
  const uint32_t oi = ObjectPos(*os, mesh, cell);
  if (oi == kNil) return false;
  const uint32_t ci = CellPos(*cs, object);
  RemoveAt(mesh, cell_spans_[mesh.value()][cell], ci, ObjectSpan(object), oi);
  return true;
}

void LocationGraph::RemoveCellLinks(MeshId mesh, uint32_t cell, std::vector<LocationObject>* removed) {
  if (FindCellSpan(mesh, cell) == nullptr) return;
  CellSpanT& cs = cell_spans_[mesh.value()][cell];
  // Front to back, as RemoveLink of each in turn would; the cell's array is
  // emptied at the end instead of shifting it once per link.
  const CellEntry* e = cell_arena_.Data(cs);
  for (uint32_t i = 0; i < cs.size; ++i) {
    const LocationObject object = e[i].object();
    if (removed != nullptr) removed->push_back(object);
    Span& os = ObjectSpan(object);
    object_arena_.Erase(os, ObjectPos(os, mesh, cell));
  }
  if (cs.unresolved != 0) LeaveUnresolved(mesh, cs);
  cs.unresolved = 0;
  num_links_ -= cs.size;
  stats_.links_removed += cs.size;
  cs.size = 0;
}

void LocationGraph::RemoveCellLinksWhere(MeshId mesh, uint32_t cell, const std::vector<uint8_t>& drop) {
  if (FindCellSpan(mesh, cell) == nullptr) return;
  CellSpanT& cs = cell_spans_[mesh.value()][cell];
  CellEntry* e = cell_arena_.Data(cs);
  const uint32_t n = std::min<uint32_t>(cs.size, static_cast<uint32_t>(drop.size()));
  uint32_t kept = 0;
  for (uint32_t i = 0; i < cs.size; ++i) {
    if (i >= n || drop[i] == 0) {
      e[kept++] = e[i];
      continue;
    }
    const LocationObject object = e[i].object();
    Span& os = ObjectSpan(object);
    object_arena_.Erase(os, ObjectPosFromBack(os, mesh, cell));
    if (e[i].unresolved() && --cs.unresolved == 0) LeaveUnresolved(mesh, cs);
  }
  num_links_ -= cs.size - kept;
  stats_.links_removed += cs.size - kept;
  cs.size = kept;
}

void LocationGraph::RemoveObjectLinks(LocationObject object, MeshId mesh, std::vector<uint32_t>* cells) {
  if (FindObjectSpan(object) == nullptr) return;
  Span& os = ObjectSpan(object);
  // One stable compaction pass over the object's array: the kept entries keep
  // their order, the removed ones are reported in link order.
  ObjectEntry* e = object_arena_.Data(os);
  uint32_t kept = 0;
  for (uint32_t i = 0; i < os.size; ++i) {
    const ObjectEntry oe = e[i];
    if (mesh.valid() && oe.mesh != mesh.value()) {
      e[kept++] = oe;
      continue;
    }
    if (cells != nullptr) cells->push_back(oe.cell);
    CellSpanT& cs = cell_spans_[oe.mesh][oe.cell];
    const uint32_t ci = CellPos(cs, object);
    if (cell_arena_.Data(cs)[ci].unresolved() && --cs.unresolved == 0) LeaveUnresolved(MeshId(oe.mesh), cs);
    cell_arena_.Erase(cs, ci);
    --num_links_;
    ++stats_.links_removed;
  }
  os.size = kept;
  if (kept == 0) object_arena_.Release(os);
}

void LocationGraph::BallsOf(MeshId mesh, uint32_t cell, std::vector<BallId>* out) const {
  const CellSpanT* cs = FindCellSpan(mesh, cell);
  if (cs == nullptr) return;
  const CellEntry* e = cell_arena_.Data(*cs);
  for (uint32_t i = 0; i < cs->size; ++i) {
    if (e[i].is_ball()) out->push_back(BallId(e[i].object_id()));
  }
}

void LocationGraph::ObjectsOf(MeshId mesh, uint32_t cell, std::vector<LocationObject>* out) const {
  const CellSpanT* cs = FindCellSpan(mesh, cell);
  if (cs == nullptr) return;
  const CellEntry* e = cell_arena_.Data(*cs);
  for (uint32_t i = 0; i < cs->size; ++i) out->push_back(e[i].object());
}

void LocationGraph::CellsOf(LocationObject object, MeshId mesh, std::vector<uint32_t>* out) const {
  const Span* os = FindObjectSpan(object);
  if (os == nullptr) return;
  const ObjectEntry* e = object_arena_.Data(*os);
  for (uint32_t i = 0; i < os->size; ++i) {
    if (e[i].mesh == mesh.value()) out->push_back(e[i].cell);
  }
}

uint32_t LocationGraph::NumUnresolved(MeshId mesh, uint32_t cell) const {
  const CellSpanT* cs = FindCellSpan(mesh, cell);
  return cs == nullptr ? 0 : cs->unresolved;
}

bool LocationGraph::Validate() const {
  // Cell side: each entry must have its partner (mesh, cell) in the object's
  // array. A duplicate object in a cell is caught from the object side.
  uint64_t count = 0;
  for (uint32_t m = 0; m < cell_spans_.size(); ++m) {
    uint64_t mesh_total = 0;
    for (uint32_t c = 0; c < cell_spans_[m].size(); ++c) {
      const CellSpanT& cs = cell_spans_[m][c];
      if (cs.size > cs.cap) return false;
      const CellEntry* e = cell_arena_.Data(cs);
      uint32_t unresolved = 0;
      for (uint32_t i = 0; i < cs.size; ++i) {
        const Span* os = FindObjectSpan(e[i].object());
        if (os == nullptr || ObjectPos(*os, MeshId(m), c) == kNil) return false;
        if (e[i].unresolved()) ++unresolved;
        ++count;
      }
      if (cs.unresolved != unresolved) return false;
      if (unresolved != 0) {
        ++mesh_total;
        const std::vector<uint32_t>& list = UnresolvedCells(MeshId(m));
        if (cs.upos >= list.size() || list[cs.upos] != c) return false;
      }
    }
    if (mesh_total != UnresolvedCells(MeshId(m)).size()) return false;
  }
  // Object side: no (mesh, cell) twice in an object's array, the cell's
  // array holds the object exactly once.
  uint64_t object_count = 0;
  for (int kind = 0; kind < 2; ++kind) {
    const util::PodVector<Span>& spans = kind == 0 ? ball_spans_ : collar_spans_;
    for (uint32_t id = 0; id < spans.size(); ++id) {
      const Span& os = spans[id];
      if (os.size > os.cap) return false;
      const LocationObject o{static_cast<ObjectKind>(kind), id};
      const ObjectEntry* e = object_arena_.Data(os);
      for (uint32_t i = 0; i < os.size; ++i) {
        for (uint32_t j = 0; j < i; ++j) {
          if (e[j].mesh == e[i].mesh && e[j].cell == e[i].cell) return false;
        }
        const CellSpanT* cs = FindCellSpan(MeshId(e[i].mesh), e[i].cell);
        if (cs == nullptr) return false;
        const CellEntry* ce = cell_arena_.Data(*cs);
        uint32_t found = 0;
        for (uint32_t j = 0; j < cs->size; ++j) found += ce[j].Is(o) ? 1 : 0;
        if (found != 1) return false;
        ++object_count;
      }
    }
  }
  return count == num_links_ && object_count == num_links_;
}

}  // namespace svrc::refine
