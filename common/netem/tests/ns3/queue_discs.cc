// ns-3's queue discs driven directly, packet by packet, as Tactile's link drives its
// disciplines: the independent implementation `tests/ns3.rs` compares against.
//
// Usage: queue_discs DISC RATE_BPS < arrivals > fates
//   DISC: droptail:P | codel | fq_codel | pie (P: the bound in packets)
//   arrivals: lines "t_ns flow bytes", in time order
//   fates: a line a packet, in arrival order: "t_ns" when its last byte left, "D" if
//   dropped.
//
// The server is the link's fixed rate exactly (tactile-netem's Link::advance_rate):
// a packet dequeued at t leaves at t + ceil(8 bytes 1e9 / rate) ns, the next one is
// dequeued then; at one instant a departure (and the dequeue after it) comes before
// an arrival, and an arrival to an idle link is dequeued on arrival. One driver event
// does all of an instant's work in that order, so ns-3's ordering of simultaneous
// events plays no part.

#include "ns3/core-module.h"
#include "ns3/network-module.h"
#include "ns3/traffic-control-module.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

using namespace ns3;

namespace
{

// A queue disc item that knows its packet's number and its flow, the flow being its
// hash (FQ-CoDel's flow queue is then `flow % flows`, as Tactile keys it).
class Item : public QueueDiscItem
{
  public:
    Item(Ptr<Packet> p, uint32_t flow, uint64_t id)
        : QueueDiscItem(p, Address(), 0),
          flow(flow),
          id(id)
    {
    }

    void AddHeader() override
    {
    }

    bool Mark() override
    {
        return false;
    }

    uint32_t Hash(uint32_t) const override
    {
        return flow;
    }

    uint32_t flow;
    uint64_t id;
};

struct Arrival
{
    uint64_t t;
    uint32_t flow;
    uint32_t bytes;
};

std::vector<Arrival> g_arrivals;
std::vector<int64_t> g_fate; // -1: pending; -2: dropped; else departure ns
Ptr<QueueDisc> g_qd;
double g_rate;
size_t g_next = 0;
Ptr<Item> g_transit;
uint64_t g_freeAt = 0;

void
OnDrop(Ptr<const QueueDiscItem> item)
{
    auto it = DynamicCast<const Item>(item);
    g_fate[it->id] = -2;
}

void
StartNext(uint64_t t)
{
    Ptr<QueueDiscItem> item = g_qd->Dequeue();
    if (!item)
    {
        g_transit = nullptr;
        return;
    }
    g_transit = DynamicCast<Item>(item);
    double bits = double(item->GetSize()) * 8.0;
    g_freeAt = t + uint64_t(std::ceil(bits * 1e9 / g_rate));
}

void
Step()
{
    uint64_t now = Simulator::Now().GetNanoSeconds();
    if (g_transit && g_freeAt == now)
    {
        g_fate[g_transit->id] = int64_t(now);
        g_transit = nullptr;
        StartNext(now);
    }
    while (g_next < g_arrivals.size() && g_arrivals[g_next].t == now)
    {
        const Arrival& a = g_arrivals[g_next];
        bool idle = !g_transit && g_qd->GetNPackets() == 0;
        Ptr<Item> item = Create<Item>(Create<Packet>(a.bytes), a.flow, g_next);
        g_next++;
        g_qd->Enqueue(item);
        if (idle)
        {
            StartNext(now);
        }
    }
    uint64_t next = std::numeric_limits<uint64_t>::max();
    if (g_transit)
    {
        next = g_freeAt;
    }
    if (g_next < g_arrivals.size())
    {
        next = std::min(next, g_arrivals[g_next].t);
    }
    if (next != std::numeric_limits<uint64_t>::max())
    {
        Simulator::Schedule(NanoSeconds(next - now), &Step);
    }
    else
    {
        // PIE's update timer runs for ever.
        Simulator::Stop();
    }
}

Ptr<QueueDisc>
Make(const std::string& disc)
{
    std::string kind = disc.substr(0, disc.find(':'));
    std::string bound = disc.find(':') == std::string::npos ? "" : disc.substr(disc.find(':') + 1);
    ObjectFactory f;
    if (kind == "droptail")
    {
        // ns-3 has drop-tail FIFOs only (FifoQueueDisc over a DropTailQueue).
        f.SetTypeId("ns3::FifoQueueDisc");
        f.Set("MaxSize", QueueSizeValue(QueueSize(bound + "p")));
    }
    else if (kind == "codel")
    {
        f.SetTypeId("ns3::CoDelQueueDisc");
        f.Set("MaxSize", QueueSizeValue(QueueSize("100000p")));
    }
    else if (kind == "fq_codel")
    {
        f.SetTypeId("ns3::FqCoDelQueueDisc");
    }
    else if (kind == "pie")
    {
        f.SetTypeId("ns3::PieQueueDisc");
        f.Set("MaxSize", QueueSizeValue(QueueSize("100000p")));
    }
    else
    {
        std::cerr << "unknown discipline " << disc << "\n";
        std::exit(2);
    }
    Ptr<QueueDisc> qd = f.Create<QueueDisc>();
    if (auto fq = DynamicCast<FqCoDelQueueDisc>(qd))
    {
        // Its default takes the device's MTU; there is no device here.
        fq->SetQuantum(1514);
    }
    qd->Initialize();
    return qd;
}

} // namespace

int
main(int argc, char** argv)
{
    if (argc != 3)
    {
        std::cerr << "usage: queue_discs DISC RATE_BPS < arrivals\n";
        return 2;
    }
    std::string disc = argv[1];
    g_rate = std::stod(argv[2]);
    Arrival a;
    while (std::scanf("%lu %u %u", &a.t, &a.flow, &a.bytes) == 3)
    {
        g_arrivals.push_back(a);
    }
    g_fate.assign(g_arrivals.size(), -1);
    g_qd = Make(disc);
    g_qd->TraceConnectWithoutContext("Drop", MakeCallback(&OnDrop));
    if (!g_arrivals.empty())
    {
        Simulator::Schedule(NanoSeconds(g_arrivals[0].t), &Step);
    }
    Simulator::Run();
    Simulator::Destroy();
    std::string out;
    out.reserve(g_fate.size() * 12);
    for (int64_t f : g_fate)
    {
        out += f == -2 ? std::string("D") : std::to_string(f);
        out += '\n';
    }
    std::fwrite(out.data(), 1, out.size(), stdout);
    return 0;
}
