// glslang reproducer (tests/tests/glslang_hlsl_buffer_length.rs): HLSL defines
// ByteAddressBuffer::GetDimensions as the buffer's size in bytes; glslang's HLSL front
// end returns OpArrayLength of its uint array, a count of 4-byte words.
ByteAddressBuffer input : register(t0);
RWByteAddressBuffer output : register(u1);

[numthreads(1, 1, 1)]
void main()
{
    uint size;
    input.GetDimensions(size);
    output.Store(0, size);
}
