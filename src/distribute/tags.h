#pragma once
// The message tags of the distributed run, in one place so that no two uses collide.
namespace radiosa {

enum Tag : int {
    kTagOrder = 1,        // rank 0 -> rank r: a work order (worker.h), or "exit"
    kTagFarmRequest = 2,  // rank r -> rank 0: last result + "next task, please" (task_farm.h)
    kTagFarmAssign = 3,   // rank 0 -> rank r: a task number, or -1: done
    kTagFailed = 4,       // rank r -> rank 0: it cannot take part (its message)
};

}  // namespace radiosa
