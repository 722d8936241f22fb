// replaced by model.cpp
