"""Chat-model interface: OpenAI-compatible client, embedded llama.cpp, response cache."""
