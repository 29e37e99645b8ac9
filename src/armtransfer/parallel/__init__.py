"""Process management: a pool whose driver sees every worker's death, the guard and reaper that
end workers with their driver, and the executors (local pool or Ray) that run a store's runs."""
